use super::*;

type Rows = Vec<(usize, Vec<String>)>;

fn split(text: &str) -> Result<(usize, Vec<String>, Rows)> {
    let t = Table::parse(text, Path::new("t.csv"), "a,b")?;
    let own = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let rows = t.rows.iter().map(|(l, f)| (*l, own(f))).collect();
    Ok((t.header_line, own(&t.names), rows))
}

#[test]
fn comments_blank_lines_quotes_crlf_and_lines() {
    let (h, names, rows) = split(
        "# c, \"unbalanced\r\n\r\n  a , \"b\"\r\n1,2\r\n   \r\n  # indented\r\n\"3\", 4 \r\n",
    )
    .unwrap();
    assert_eq!(h, 3);
    assert_eq!(names, ["a", "b"]);
    assert_eq!(rows[0], (4, vec!["1".to_string(), "2".into()]));
    assert_eq!(rows[1], (7, vec!["3".to_string(), "4".into()]));
}

#[test]
fn semicolons_tabs_bom_and_trailing_commas() {
    for text in [
        "a;b\n1;2\n",
        "a\tb\n1\t2\n",
        "\u{FEFF}a,b\n1,2\n",
        "a,b,\n1,2,\n",
        "a,b\n1,2,,\n",
    ] {
        let (_, names, rows) = split(text).unwrap();
        assert_eq!(names, ["a", "b"], "{text:?}");
        assert_eq!(rows[0].1, ["1", "2"], "{text:?}");
    }
}

#[test]
fn wrong_widths_and_escaped_quotes_name_the_line() {
    let e = split("a,b\n1,2\n1,2,3\n").err().unwrap().to_string();
    assert!(e.starts_with("t.csv:3: 3 fields, the header has 2"), "{e}");
    let e = split("a,b\n\"1\"\"2\",2\n").err().unwrap().to_string();
    assert!(e.starts_with("t.csv:2: field `1\"2`"), "{e}");
    let e = split("# only a comment\n").err().unwrap().to_string();
    assert!(
        e.starts_with("t.csv:1: empty file: expected a header such as `a,b`"),
        "{e}"
    );
}

#[test]
fn utf16_is_decoded_and_binary_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("u.csv");
    let mut bytes = vec![0xFF, 0xFE];
    for u in "a,b\r\n1,2\r\n".encode_utf16() {
        bytes.extend(u.to_le_bytes());
    }
    std::fs::write(&p, &bytes).unwrap();
    assert_eq!(read_text(&p).unwrap(), "a,b\r\n1,2\r\n");
    let mut r = TableReader::new(&bytes[..], &p, "a,b").unwrap();
    assert_eq!(r.names, ["a", "b"]);
    assert_eq!(r.next_row().unwrap(), Some(2));
    assert_eq!(r.fields().collect::<Vec<_>>(), ["1", "2"]);
    assert_eq!(r.next_row().unwrap(), None);
    std::fs::write(&p, b"a,b\n1,2\n\x80\xff\x00,1\n").unwrap();
    let e = read_text(&p).unwrap_err().to_string();
    assert!(e.contains("u.csv:3: not UTF-8 text"), "{e}");
    let mut r = TableReader::new(&b"a,b\n1,2\n\x80\xff,1\n"[..], &p, "a,b").unwrap();
    assert_eq!(r.next_row().unwrap(), Some(2));
    let e = r.next_row().unwrap_err().to_string();
    assert!(e.contains("u.csv:3: not UTF-8 text"), "{e}");
}
