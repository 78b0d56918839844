//! The fast reader against toml's: on every text it accepts, the same
//! table; never a text toml refuses; and the ordinary forms of a scenario
//! file are all accepted (not left to toml).

use super::read;
use toml::Value;

/// Equal tables, floats bit for bit (so NaN equals itself).
fn same(a: &toml::Table, b: &toml::Table) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|((ka, va), (kb, vb))| ka == kb && same_value(va, vb))
}

fn same_value(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Float(x), Value::Float(y)) => x.to_bits() == y.to_bits(),
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(x, y)| same_value(x, y))
        }
        (Value::Table(x), Value::Table(y)) => same(x, y),
        _ => a == b,
    }
}

/// Documents with the ordinary forms: read here, as toml reads them.
const ORDINARY: &[&str] = &[
    "",
    "# only a comment\n",
    "a = 1\nb = -2\nc = +3\nd = 1_000\n",
    "hex = 0xff\noct = 0o17\nbin = 0b101\n",
    "f = 1.5\ng = -0.0\nh = 1e-8\ni = 6.02E+23\nj = 1_000.5\nk = inf\nl = -inf\nm = nan\n",
    "s = \"basic \\\"quoted\\\" \\u00e9\\n\"\nt = 'literal \\n'\n",
    "u = \"\"\"\nmulti\nline\"\"\"\nv = '''\nraw\n'''\n",
    "b1 = true\nb2 = false\n",
    "d1 = 1979-05-27T07:32:00Z\nd2 = 1979-05-27\nd3 = 07:32:00\nd4 = 1979-05-27T00:32:00.999999-07:00\n",
    "a = [1, 2, 3]\nb = [[1.0, 0.0], [0.0, 1.0]]\nc = []\nd = [\n  1,\n  2, # two\n]\n",
    "p = { x = 1, y = { z = 2 } }\nq = {}\n",
    "p = { a.b = 1, a.c = 2 }\n",
    "a.b.c = 1\na.b.d = 2\na.e = 3\n",
    "\"quoted key\" = 1\n'literal key' = 2\n\"\" = 3\n",
    "[t]\nx = 1\n[t.u]\ny = 2\n[v.w]\nz = 3\n[v]\nq = 4\n",
    "[[a]]\nid = 1\n[a.sub]\nx = 1\n[[a]]\nid = 2\n[[a.list]]\ny = 1\n[[a.list]]\ny = 2\n",
    "[ spaced . header ]\nx = 1\n[\"quoted\".'both']\ny = 2\n",
    "[a]\nb.c = 1\nb.d = 2\n",
    "x = 1 # trailing comment\r\ny = 2\r\n",
    "\u{feff}bom = 1\n",
    "aot = [{ a = 1 }, { a = 2 }]\n",
];

/// Documents toml refuses: never accepted here.
const INVALID: &[&str] = &[
    "a = \n",
    "a = 1\na = 2\n",
    "[t]\n[t]\n",
    "a.b = 1\n[a]\nc = 2\n",
    "[a]\nb = 1\n[a.b]\nc = 2\n",
    "a = [1, 2\n",
    "a = 1]\n",
    "[a\n",
    "[[a]]\n[a]\n",
    "a = [1]\n[[a]]\n",
    "p = { x = 1 }\n[p]\ny = 2\n",
    "p = { x = 1 }\np.y = 2\n",
    "p = { x = 1, x = 2 }\n",
    "p = { a = { b = 1 }, a.c = 2 }\n",
    "i = 9223372036854775808\n",
    "f = 1e999\n",
    "d = 1979-13-45\n",
    "s = \"unterminated\n",
    "s = \"bad \\q escape\"\n",
    "k = 01\n",
    "f = .5\n",
    "f = 1.\n",
    "a = 1 b = 2\n",
    "# bad \u{7} comment\n",
    "= 1\n",
    "a = 1\n]\n",
    "[]\n",
    "a.b = 1\na.b.c = 2\n",
];

/// `read`'s table is toml's whenever `read` accepts; `read` refuses
/// whatever toml refuses.
#[track_caller]
fn consistent(text: &str) {
    match (read(text), text.parse::<toml::Table>()) {
        (Some(tree), Ok(toml)) => assert!(same(&tree.to_toml(), &toml), "{text:?}: {tree:?}"),
        (Some(tree), Err(e)) => panic!("{text:?} accepted as {tree:?}; toml: {e}"),
        (None, _) => {}
    }
}

#[test]
fn the_ordinary_forms_are_read_as_toml_reads_them() {
    for text in ORDINARY {
        let toml: toml::Table = text
            .parse()
            .unwrap_or_else(|e| panic!("{text:?} is TOML: {e}"));
        let tree = read(text).unwrap_or_else(|| panic!("{text:?} left to toml"));
        assert!(
            same(&tree.to_toml(), &toml),
            "{text:?}: {tree:?} vs {toml:?}"
        );
    }
}

#[test]
fn nothing_toml_refuses_is_accepted() {
    for text in INVALID {
        assert!(text.parse::<toml::Table>().is_err(), "{text:?} is TOML");
        assert!(read(text).is_none(), "{text:?} accepted");
    }
}

#[test]
fn documents_longer_than_a_chunk_read_the_same() {
    let mut text = String::from("title = \"many\"\n");
    for i in 0..30_000 {
        text.push_str(&format!(
            "[[agent]]\nid = {i}\nomega = [\n  {i}.5,\n  -1e-3, 2.0 ]\n[agent.attitude]\nangle = {{ deg = {i} }}\n"
        ));
    }
    text.push_str("[tail]\nx = 'end'\n");
    assert!(text.len() / 4 > super::CHUNK_TOKENS, "several chunks");
    let toml: toml::Table = text.parse().unwrap();
    assert!(same(&read(&text).expect("read here").to_toml(), &toml));
    // An error in a later chunk is still found.
    let bad = text.replace("id = 29000\n", "id = 29000\nid = 1\n");
    assert!(bad.parse::<toml::Table>().is_err());
    assert!(read(&bad).is_none());
}

#[test]
fn a_document_serialises_as_tomls_table() {
    for text in ORDINARY {
        let toml: toml::Table = text.parse().unwrap();
        let tree = read(text).unwrap();
        assert_eq!(
            toml::to_string(&tree).unwrap(),
            toml::to_string(&toml).unwrap(),
            "{text:?}"
        );
    }
}

#[test]
fn nesting_and_dotted_keys_at_tomls_limit_agree() {
    for depth in [2, 79, 80, 81, 200] {
        consistent(&format!(
            "x = {}1{}\n",
            "[".repeat(depth),
            "]".repeat(depth)
        ));
        consistent(&format!(
            "x = {}{}\n",
            "{ a = ".repeat(depth),
            "}".repeat(depth)
        ));
        let keys = vec!["k"; depth].join(".");
        consistent(&format!("{keys} = 1\n"));
        consistent(&format!("[{keys}]\nx = 1\n"));
    }
}

#[test]
fn every_case_agrees_with_toml() {
    for text in ORDINARY.iter().chain(INVALID) {
        consistent(text);
    }
}
