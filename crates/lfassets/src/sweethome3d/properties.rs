//! Java `.properties` files, the format of Sweet Home 3D's furniture catalogues, and the
//! catalogue entries (`field#N` keys) they hold.

use std::collections::{BTreeMap, HashMap};

/// Decodes a `.properties` file the way Java 9+ resource bundles do: UTF-8 when the bytes are
/// valid UTF-8, else ISO-8859-1 (every byte one character).
pub fn decode_properties(bytes: &[u8]) -> String {
    match std::str::from_utf8(bytes) {
        Ok(s) => s.to_string(),
        Err(_) => bytes.iter().map(|&b| char::from(b)).collect(),
    }
}

/// Parses Java `.properties` text (`java.util.Properties.load` rules): `#`/`!` comment lines,
/// `key=value`, `key:value` or `key value`, a backslash at the end of a line continues it on
/// the next (whose leading blanks are dropped), escapes `\t \n \r \f \uXXXX` and `\x` → `x`.
/// Pairs come in file order; later duplicates win when collected into a map.
///
/// Hand-written (about 80 lines, tested below) rather than the `java-properties` crate: that
/// crate decodes "ISO-8859-1" as windows-1252 through `encoding_rs` (bytes 0x80–0x9F differ),
/// does not do Java 9's UTF-8-first reading, and would add two dependencies to the build.
pub fn parse_properties(text: &str) -> Vec<(String, String)> {
    let text = text.replace("\r\n", "\n").replace('\r', "\n");
    let mut pairs = Vec::new();
    let mut logical = String::new();
    let mut continuing = false;
    for raw in text.split('\n') {
        let line = raw.trim_start_matches([' ', '\t', '\x0c']);
        if !continuing && (line.is_empty() || line.starts_with('#') || line.starts_with('!')) {
            continue;
        }
        let backslashes = line.bytes().rev().take_while(|&b| b == b'\\').count();
        if backslashes % 2 == 1 {
            logical.push_str(&line[..line.len() - 1]);
            continuing = true;
            continue;
        }
        logical.push_str(line);
        continuing = false;
        pairs.push(split_key_value(&logical));
        logical.clear();
    }
    if continuing {
        pairs.push(split_key_value(&logical));
    }
    pairs
}

/// Splits a logical line at the first unescaped `=`, `:` or blank.
fn split_key_value(line: &str) -> (String, String) {
    let is_blank = |c: char| matches!(c, ' ' | '\t' | '\x0c');
    let mut key_end = line.len();
    let mut escaped = false;
    for (i, c) in line.char_indices() {
        if escaped {
            escaped = false;
        } else if c == '\\' {
            escaped = true;
        } else if c == '=' || c == ':' || is_blank(c) {
            key_end = i;
            break;
        }
    }
    let mut rest = line[key_end..].trim_start_matches(is_blank);
    if let Some(r) = rest.strip_prefix(['=', ':']) {
        rest = r.trim_start_matches(is_blank);
    }
    (unescape(&line[..key_end]), unescape(rest))
}

/// Resolves the escapes of a key or value (`\uXXXX` surrogate pairs combined).
fn unescape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars().peekable();
    let mut pending_high: Option<u32> = None;
    while let Some(c) = chars.next() {
        let decoded = if c != '\\' {
            Some(c)
        } else {
            match chars.next() {
                None => None,
                Some('t') => Some('\t'),
                Some('n') => Some('\n'),
                Some('r') => Some('\r'),
                Some('f') => Some('\x0c'),
                Some('u') => {
                    let hex: String = chars.clone().take(4).collect();
                    match u32::from_str_radix(&hex, 16) {
                        Ok(unit) if hex.len() == 4 => {
                            for _ in 0..4 {
                                chars.next();
                            }
                            if (0xD800..0xDC00).contains(&unit) {
                                if pending_high.replace(unit).is_some() {
                                    out.push(char::REPLACEMENT_CHARACTER);
                                }
                                continue;
                            }
                            if (0xDC00..0xE000).contains(&unit) {
                                let c = pending_high.take().and_then(|high| {
                                    char::from_u32(
                                        0x10000 + ((high - 0xD800) << 10) + (unit - 0xDC00),
                                    )
                                });
                                out.push(c.unwrap_or(char::REPLACEMENT_CHARACTER));
                                continue;
                            }
                            char::from_u32(unit)
                        }
                        _ => Some('u'),
                    }
                }
                Some(other) => Some(other),
            }
        };
        if pending_high.take().is_some() {
            out.push(char::REPLACEMENT_CHARACTER);
        }
        if let Some(c) = decoded {
            out.push(c);
        }
    }
    if pending_high.is_some() {
        out.push(char::REPLACEMENT_CHARACTER);
    }
    out
}

/// The furniture entries of a catalogue: entry `N` holds the fields of the keys `field#N`,
/// in increasing `N`.
pub(super) fn catalogue_entries(
    pairs: &[(String, String)],
) -> Vec<(usize, HashMap<String, String>)> {
    let mut entries: BTreeMap<usize, HashMap<String, String>> = BTreeMap::new();
    for (key, value) in pairs {
        let Some((field, index)) = key.rsplit_once('#') else {
            continue;
        };
        let Ok(index) = index.parse::<usize>() else {
            continue;
        };
        if field.is_empty() || !field.chars().all(|c| c.is_ascii_alphanumeric()) {
            continue;
        }
        entries
            .entry(index)
            .or_default()
            .insert(field.to_string(), value.clone());
    }
    entries
        .into_iter()
        .filter(|(_, e)| e.contains_key("model") || e.contains_key("name"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn properties_comments_separators_and_escapes() {
        let text = "# comment\n! other comment\n   \nid=SweetHome3D#Lib\n\
                    name#1 = Chair \\u00e9t\\u00E9\n\
                    width#1:45\nkey\\ with\\=stuff value\\tx\nempty#1=\nsurrogate=\\uD83C\\uDF10\n";
        let pairs = parse_properties(text);
        let map: HashMap<_, _> = pairs.iter().cloned().collect();
        assert_eq!(map["id"], "SweetHome3D#Lib");
        assert_eq!(map["name#1"], "Chair été");
        assert_eq!(map["width#1"], "45");
        assert_eq!(map["key with=stuff"], "value\tx");
        assert_eq!(map["empty#1"], "");
        assert_eq!(map["surrogate"], "🌐");
        assert_eq!(pairs.len(), 6);
    }

    #[test]
    fn properties_continuations_and_latin1() {
        let text =
            "tags#2=a, \\\n    b, \\\r\n  c\nback=ends with \\\\\nnext=1\n#not=a key\nlast=x\\";
        let map: HashMap<_, _> = parse_properties(text).into_iter().collect();
        assert_eq!(map["tags#2"], "a, b, c");
        assert_eq!(map["back"], "ends with \\");
        assert_eq!(map["next"], "1");
        assert_eq!(map["last"], "x");
        assert!(!map.contains_key("#not"));
        // ISO-8859-1 bytes (invalid UTF-8) and UTF-8 both decode.
        assert_eq!(decode_properties(b"name=H\xf4i An"), "name=Hôi An");
        assert_eq!(decode_properties("name=Hôi An".as_bytes()), "name=Hôi An");
    }
}
