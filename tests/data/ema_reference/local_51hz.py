"""Issue 33: why the pyuff 51.5 Hz damping differs from the LSCF reference.

A local fit of tests/data/pyuff/frf_10_990.csv over 40-64 Hz, all three channels, weights
1/sigma with sigma = 3 std/sqrt(2) (the noise of tests/data/pyuff_rigid.toml): per channel a
free complex background (constant + linear in frequency) plus one accelerance mode
-w^2 R/(wn^2 - w^2 + 2j z wn w), R real (rshape's modal model) or complex (LSFD's).  The
profile over z (wn on a 0.001 Hz grid, the linear terms by least squares) gives the estimate
and the 95 % likelihood-ratio interval (V - V_min <= 1.92, V = sum |e|^2 / sigma^2).
Independent of rshape (numpy only).  Run from the repository root:
    python3 tests/data/ema_reference/local_51hz.py
Output (numpy 2.4.6):
    real residue zeta_hat 0.000424 V 706.2  95% interval 0.000189-0.000599
    complex residue zeta_hat 0.000533 V 123.0  95% interval 0.000378-0.000754
"""
import numpy as np
d=np.loadtxt('tests/data/pyuff/frf_10_990.csv',delimiter=',',skiprows=1)
s=np.loadtxt('tests/data/pyuff/frf_10_990_std.csv',delimiter=',',skiprows=1)
sel=(d[:,0]>=40)&(d[:,0]<=64)
f=d[sel,0]; w=2*np.pi*f
H=np.array([d[sel,1+2*j]+1j*d[sel,2+2*j] for j in range(3)])
sig=3*s[sel,1:4].T/np.sqrt(2)
def V(wn,z,cplx):
    tot=0
    for j in range(3):
        m=-w**2/(wn**2-w**2+2j*z*wn*w)
        cols=[np.ones_like(w)+0j,1j*np.ones_like(w),(w-w.mean())/w.mean()+0j,1j*(w-w.mean())/w.mean(), m]
        if cplx: cols.append(1j*m)
        A=np.array(cols).T/sig[j][:,None]
        y=H[j]/sig[j]
        Ar=np.vstack([A.real,A.imag]); yr=np.concatenate([y.real,y.imag])
        x,*_=np.linalg.lstsq(Ar,yr,rcond=None)
        tot+=np.sum((yr-Ar@x)**2)
    return tot
for cplx in (False,True):
    zs=np.geomspace(3e-5,3e-3,41)
    prof=[]
    for z in zs:
        prof.append(min(V(2*np.pi*fn,z,cplx) for fn in np.linspace(51.40,51.65,251)))
    prof=np.array(prof); i=prof.argmin()
    ok=zs[prof-prof.min()<=1.92]
    print("complex residue" if cplx else "real residue", "zeta_hat %.3g V %.1f  95%% interval %.3g-%.3g"%(zs[i],prof[i],ok.min(),ok.max()))
