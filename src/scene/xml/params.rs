//! `$name` substitution in attribute values, as Mitsuba 3.9 does it.
//!
//! The parameters are the `-D name=value` defines plus every `<default name value>` met so far in
//! document order (a default never overrides a define or an earlier default). Substitution is
//! textual: each key `$name` is replaced wherever it occurs, longest keys first (so `$ab` wins
//! over `$a`, and `$abc` with only `$ab` defined reads as the value of `ab` followed by `c`).
//! A `$` preceded by a backslash is left alone and the backslash removed; any `$` left over after
//! substitution is an undefined parameter. A define that is never substituted is an error.

/// One substitution key.
#[derive(Clone, Debug)]
struct Param {
    /// `"$name"`.
    key: String,
    value: String,
    used: bool,
}

/// The parameters, longest key first.
#[derive(Clone, Debug, Default)]
pub struct Params {
    list: Vec<Param>,
}

impl Params {
    /// The `-D` defines, in the order given. A later define of the same name is ignored.
    pub fn from_defines(defines: &[(String, String)]) -> Params {
        let mut list: Vec<Param> = Vec::new();
        for (k, v) in defines {
            let key = format!("${k}");
            if list.iter().all(|p| p.key != key) {
                list.push(Param { key, value: v.clone(), used: false });
            }
        }
        // Stable: equal lengths keep their order.
        list.sort_by_key(|p| std::cmp::Reverse(p.key.len()));
        Params { list }
    }

    /// `<default name value>`: define `name` unless it already is. Defaults never count as unused.
    pub fn add_default(&mut self, name: &str, value: &str) {
        if self.list.iter().any(|p| &p.key[1..] == name) {
            return;
        }
        let key = format!("${name}");
        let at = self.list.iter().position(|p| key.len() > p.key.len()).unwrap_or(self.list.len());
        self.list.insert(at, Param { key, value: value.to_string(), used: true });
    }

    /// Substitute every parameter in `s`. `Err(name)` names the first undefined `$name`.
    pub fn substitute(&mut self, s: &str) -> Result<String, String> {
        if !s.contains('$') {
            return Ok(s.to_string());
        }
        let mut value = s.to_string();
        for p in &mut self.list {
            let mut pos = 0;
            while let Some(found) = value.get(pos..).and_then(|rest| rest.find(&p.key)) {
                let i = pos + found;
                if i > 0 && value.as_bytes()[i - 1] == b'\\' {
                    pos = i + p.key.len();
                } else {
                    value.replace_range(i..i + p.key.len(), &p.value);
                    p.used = true;
                    pos = i + p.value.len();
                }
            }
        }
        let bytes = value.as_bytes();
        for (i, &b) in bytes.iter().enumerate() {
            if b == b'$' && !(i > 0 && bytes[i - 1] == b'\\') {
                let name: String =
                    value[i + 1..].chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
                return Err(name);
            }
        }
        Ok(value.replace("\\$", "$"))
    }

    /// The `-D` defines that were never substituted, as `name=value`.
    pub fn unused(&self) -> Vec<String> {
        self.list.iter().filter(|p| !p.used).map(|p| format!("{}={}", &p.key[1..], p.value)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn defines(d: &[(&str, &str)]) -> Params {
        let v: Vec<(String, String)> = d.iter().map(|(a, b)| (a.to_string(), b.to_string())).collect();
        Params::from_defines(&v)
    }

    #[test]
    fn longest_key_first_and_textual() {
        // Mitsuba 3.9.1: defaults ab=X, a=Y; "$ab $a $abc" -> "X Y Xc".
        let mut p = Params::default();
        p.add_default("ab", "X");
        p.add_default("a", "Y");
        assert_eq!(p.substitute("$ab $a $abc").unwrap(), "X Y Xc");
    }

    #[test]
    fn defines_win_over_defaults() {
        let mut p = defines(&[("spp", "8")]);
        p.add_default("spp", "4");
        assert_eq!(p.substitute("$spp").unwrap(), "8");
        assert!(p.unused().is_empty());
    }

    #[test]
    fn escapes_and_undefined() {
        let mut p = defines(&[("x", "1")]);
        assert_eq!(p.substitute("\\$x").unwrap(), "$x");
        assert_eq!(p.unused(), vec!["x=1".to_string()]);
        assert_eq!(p.substitute("$$x"), Err("1".to_string()));
        assert_eq!(p.substitute("$x-y").unwrap(), "1-y");
        assert_eq!(p.substitute("a$"), Err(String::new()));
        assert_eq!(p.substitute("${x}"), Err(String::new()));
        assert_eq!(p.substitute("$é"), Err(String::new()));
    }
}
