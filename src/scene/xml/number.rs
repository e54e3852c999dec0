//! Value syntax as Mitsuba 3.9 reads it: numbers (`string::stof`, `std::from_chars`), booleans,
//! token lists, version numbers and the camelCase → snake_case rename of old scenes.

/// A version number `major.minor.patch`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Version(pub u32, pub u32, pub u32);

impl std::fmt::Display for Version {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}.{}.{}", self.0, self.1, self.2)
    }
}

/// Parse `"M.m.p"` (surrounding spaces allowed): three non-empty decimal parts.
pub fn parse_version(s: &str) -> Option<Version> {
    let parts: Vec<&str> = s.trim_matches([' ', '\t']).split('.').collect();
    let [a, b, c] = parts.as_slice() else { return None };
    let num = |p: &str| -> Option<u32> {
        if p.is_empty() || !p.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        p.parse().ok()
    };
    Some(Version(num(a)?, num(b)?, num(c)?))
}

/// A floating point number like Mitsuba's `string::stof<double>`: spaces and tabs around it,
/// one optional leading `+`, decimal or scientific notation, `inf`/`infinity`/`nan`/`nan(...)`
/// in any case. Trailing garbage is an error; an empty or blank string reads as 0 (as in
/// Mitsuba 3.9).
pub fn parse_float(s: &str) -> Option<f64> {
    let t = s.trim_matches([' ', '\t']);
    if t.is_empty() {
        return Some(0.0);
    }
    let t = t.strip_prefix('+').unwrap_or(t);
    if t.is_empty() || t.starts_with('+') {
        return None;
    }
    let body = t.strip_prefix('-').unwrap_or(t);
    let lower = body.to_ascii_lowercase();
    if let Some(inner) = lower.strip_prefix("nan(").and_then(|r| r.strip_suffix(')')) {
        return inner.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_').then_some(f64::NAN);
    }
    // Rust's grammar accepts what fast_float accepts once the sign is handled; reject the
    // few forms it takes that fast_float does not (a second sign, inner spaces are rejected
    // by both).
    if body.starts_with(['+', '-']) {
        return None;
    }
    t.parse::<f64>().ok()
}

/// C's `isspace` in the "C" locale.
fn is_c_space(c: char) -> bool {
    matches!(c, ' ' | '\t' | '\n' | '\x0b' | '\x0c' | '\r')
}

/// An integer like Mitsuba's `<integer>`: `std::from_chars` into an `int64_t` with surrounding
/// whitespace allowed; a `+` sign, a fraction, an exponent or an overflow are errors.
pub fn parse_int(s: &str) -> Option<i64> {
    let t = s.trim_matches(is_c_space);
    if t.starts_with('+') {
        return None;
    }
    t.parse::<i64>().ok()
}

/// `true` / `false` in any letter case, nothing else (no surrounding spaces).
pub fn parse_bool(s: &str) -> Option<bool> {
    if s.eq_ignore_ascii_case("true") {
        Some(true)
    } else if s.eq_ignore_ascii_case("false") {
        Some(false)
    } else {
        None
    }
}

/// Split at any of the delimiter characters, dropping empty pieces (Mitsuba's `tokenize`;
/// its default delimiters are `", "`).
pub fn tokenize<'a>(s: &'a str, delims: &[char]) -> Vec<&'a str> {
    s.split(|c| delims.contains(&c)).filter(|t| !t.is_empty()).collect()
}

/// Comma/space separated tokens (the delimiters Mitsuba uses for vectors and colours).
pub fn tokens(s: &str) -> Vec<&str> {
    tokenize(s, &[',', ' '])
}

/// Mitsuba's `camel_to_underscore_case`: an upper-case letter that follows a lower-case one
/// starts a new word; the upper-case letters right after it are lowered too
/// (`maxDepth` → `max_depth`, `intIOR` → `int_ior`, `fooBARBaz` → `foo_barbaz`).
pub fn camel_to_snake(name: &str) -> String {
    let b = name.as_bytes();
    let mut out = String::with_capacity(name.len() + 4);
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if i > 0 && b[i - 1].is_ascii_lowercase() && c.is_ascii_uppercase() {
            out.push('_');
            out.push(c.to_ascii_lowercase() as char);
            while i + 1 < b.len() && b[i + 1].is_ascii_uppercase() {
                i += 1;
                out.push(b[i].to_ascii_lowercase() as char);
            }
            i += 1;
        } else {
            // Copy one whole character (non-ASCII bytes are never upper/lower case here).
            let ch_len = name[i..].chars().next().map_or(1, char::len_utf8);
            out.push_str(&name[i..i + ch_len]);
            i += ch_len;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_like_mitsuba() {
        // Accepted by Mitsuba 3.9.1 (checked with mi.parser.parse_string).
        for (s, v) in [
            ("1e3", 1e3),
            ("+2", 2.0),
            (".5", 0.5),
            ("5.", 5.0),
            ("\t1\t", 1.0),
            (" +1", 1.0),
            ("+-1", -1.0),
            ("1.e3", 1e3),
            ("  .5  ", 0.5),
            ("00012", 12.0),
            ("1E+02", 100.0),
            ("", 0.0),
            (" ", 0.0),
            ("1e-400", 0.0),
        ] {
            assert_eq!(parse_float(s), Some(v), "{s:?}");
        }
        for s in ["inf", "INF", "+inf", "infinity", "inF", "1e400"] {
            assert_eq!(parse_float(s), Some(f64::INFINITY), "{s:?}");
        }
        assert_eq!(parse_float("-inf"), Some(f64::NEG_INFINITY));
        for s in ["nan", "NaN", "-nan", "+nan", "nan(1)"] {
            assert!(parse_float(s).unwrap().is_nan(), "{s:?}");
        }
        // Rejected by Mitsuba 3.9.1.
        for s in [
            "0x10", "1 2", "1,", "1e", "1e+", "-", ".", "++1", "1.5f", "1_0", "1d3", "+", " + ", "- ", "1e5 x", ".e3",
            "1..2", "1e5x", "infin", "+ 1",
        ] {
            assert_eq!(parse_float(s), None, "{s:?}");
        }
    }

    #[test]
    fn integers_like_mitsuba() {
        assert_eq!(parse_int(" 12 "), Some(12));
        assert_eq!(parse_int("-3"), Some(-3));
        assert_eq!(parse_int("-0"), Some(0));
        assert_eq!(parse_int("9223372036854775807"), Some(i64::MAX));
        for s in ["+3", "1.5", "99999999999999999999", "0x10", "1e3", "", "- 1"] {
            assert_eq!(parse_int(s), None, "{s:?}");
        }
    }

    #[test]
    fn booleans_like_mitsuba() {
        assert_eq!(parse_bool("TRUE"), Some(true));
        assert_eq!(parse_bool("False"), Some(false));
        for s in ["1", " true", "yes", ""] {
            assert_eq!(parse_bool(s), None);
        }
    }

    #[test]
    fn versions() {
        assert_eq!(parse_version("3.0.0"), Some(Version(3, 0, 0)));
        assert_eq!(parse_version(" 0.6.0 "), Some(Version(0, 6, 0)));
        for s in ["3.0", "3", "3.0.0.1", "v3.0.0", "3.a.0", "", "3..0", "3.0.x"] {
            assert_eq!(parse_version(s), None, "{s:?}");
        }
        assert!(Version(1, 9, 9) < Version(2, 0, 0));
    }

    #[test]
    fn snake_case_like_mitsuba() {
        // Outputs of Mitsuba 3.9.1's transform_upgrade.
        for (a, b) in [
            ("maxDepth", "max_depth"),
            ("intIOR", "int_ior"),
            ("fooBARBaz", "foo_barbaz"),
            ("ABc", "ABc"),
            ("a1B", "a1B"),
            ("aB1cD", "a_b1c_d"),
            ("toWorld", "to_world"),
            ("_arg_3", "_arg_3"),
            ("éB", "éB"),
        ] {
            assert_eq!(camel_to_snake(a), b);
        }
    }

    #[test]
    fn tokenizing() {
        assert_eq!(tokens("0.1, 0.2,  0.3"), vec!["0.1", "0.2", "0.3"]);
        assert_eq!(tokenize("400::0.1", &[':']), vec!["400", "0.1"]);
    }
}
