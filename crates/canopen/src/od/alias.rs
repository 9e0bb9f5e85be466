//! Vendor parameter aliases: rules like `F{x:hex}.{y:hex}.{z:hex}` -> index/sub.

use super::expr::Expr;

/// One piece of an alias pattern.
#[derive(Clone, Debug, PartialEq)]
enum Piece {
    /// Literal text, matched case-insensitively.
    Lit(char),
    /// A placeholder: name and radix (10 or 16).
    Var(String, u32),
}

/// A rule that turns a family of vendor parameter numbers into objects.
#[derive(Clone, Debug, PartialEq)]
pub struct AliasRule {
    /// The pattern as written, e.g. `F{x:hex}.{y:hex}.{z:hex}`.
    pub pattern: String,
    pieces: Vec<Piece>,
    /// Index from the placeholders.
    pub index: Expr,
    /// Sub-index from the placeholders.
    pub sub: Expr,
    /// Help text.
    pub description: Option<String>,
}

/// What is wrong with an alias rule of a profile.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum AliasError {
    #[error("`{expr}` uses `{variable}`, which is not a placeholder of `{pattern}`")]
    NotAPlaceholder {
        expr: String,
        variable: String,
        pattern: String,
    },
    #[error("placeholder kind `{kind}` in `{pattern}` (use dec or hex)")]
    PlaceholderKind { kind: String, pattern: String },
    /// `inner` is the text between the braces.
    #[error("bad placeholder `{{{inner}}}` in `{pattern}`")]
    BadPlaceholder { inner: String, pattern: String },
    #[error("placeholders need a separator between them in `{0}`")]
    NoSeparator(String),
    #[error("pattern `{0}` has no placeholder")]
    NoPlaceholder(String),
}

/// Why a typed object does not resolve to (index, sub).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ObjectError {
    #[error("empty object")]
    Empty,
    #[error("unknown object `{text}` (use 0xINDEX[:SUB], a name or a vendor alias of profile {profile})")]
    Unknown { text: String, profile: String },
}

impl AliasRule {
    /// A rule from its pattern and expressions; checks that the expressions
    /// only use the pattern's placeholders.
    pub fn new(pattern: &str, index: Expr, sub: Expr, description: Option<String>) -> Result<AliasRule, AliasError> {
        let pieces = parse_pattern(pattern)?;
        let names: Vec<&str> = pieces
            .iter()
            .filter_map(|p| match p {
                Piece::Var(n, _) => Some(n.as_str()),
                Piece::Lit(_) => None,
            })
            .collect();
        for e in [&index, &sub] {
            if let Some(v) = e.variables().into_iter().find(|v| !names.contains(v)) {
                return Err(AliasError::NotAPlaceholder {
                    expr: e.to_string(),
                    variable: v.to_string(),
                    pattern: pattern.to_string(),
                });
            }
        }
        Ok(AliasRule {
            pattern: pattern.to_string(),
            pieces,
            index,
            sub,
            description,
        })
    }

    /// The (index, sub) for `text` when the whole text matches the pattern.
    pub fn apply(&self, text: &str) -> Option<(u16, u8)> {
        let vars = match_pieces(&self.pieces, &text.trim().chars().collect::<Vec<_>>())?;
        let lookup = |n: &str| vars.iter().find(|(k, _)| k == n).map(|(_, v)| *v);
        let index = u16::try_from(self.index.eval(&lookup).ok()?).ok()?;
        let sub = u8::try_from(self.sub.eval(&lookup).ok()?).ok()?;
        Some((index, sub))
    }
}

fn parse_pattern(pattern: &str) -> Result<Vec<Piece>, AliasError> {
    let mut pieces = Vec::new();
    let mut chars = pattern.chars();
    while let Some(c) = chars.next() {
        if c != '{' {
            pieces.push(Piece::Lit(c));
            continue;
        }
        let inner: String = chars.by_ref().take_while(|c| *c != '}').collect();
        let (name, kind) = inner.split_once(':').unwrap_or((inner.as_str(), "dec"));
        let radix = match kind.trim() {
            "dec" => 10,
            "hex" => 16,
            other => {
                return Err(AliasError::PlaceholderKind {
                    kind: other.to_string(),
                    pattern: pattern.to_string(),
                });
            }
        };
        let name = name.trim();
        if name.is_empty() || !name.chars().all(|c| c.is_alphanumeric() || c == '_') {
            return Err(AliasError::BadPlaceholder {
                inner,
                pattern: pattern.to_string(),
            });
        }
        if matches!(pieces.last(), Some(Piece::Var(..))) {
            return Err(AliasError::NoSeparator(pattern.to_string()));
        }
        pieces.push(Piece::Var(name.to_string(), radix));
    }
    if !pieces.iter().any(|p| matches!(p, Piece::Var(..))) {
        return Err(AliasError::NoPlaceholder(pattern.to_string()));
    }
    Ok(pieces)
}

fn match_pieces(pieces: &[Piece], text: &[char]) -> Option<Vec<(String, i64)>> {
    let mut vars = Vec::new();
    let mut pos = 0;
    for (i, piece) in pieces.iter().enumerate() {
        match piece {
            Piece::Lit(c) => {
                if !text.get(pos)?.eq_ignore_ascii_case(c) {
                    return None;
                }
                pos += 1;
            }
            Piece::Var(name, radix) => {
                let stop = match pieces.get(i + 1) {
                    Some(Piece::Lit(c)) => Some(*c),
                    _ => None,
                };
                let start = pos;
                while pos < text.len() && text[pos].is_digit(*radix) && Some(text[pos]) != stop {
                    pos += 1;
                }
                if pos == start || pos - start > 15 {
                    return None;
                }
                let digits: String = text[start..pos].iter().collect();
                vars.push((name.clone(), i64::from_str_radix(&digits, *radix).ok()?));
            }
        }
    }
    (pos == text.len()).then_some(vars)
}

/// Parses an index form: `0x6041`, `0x1018:1`, `0x1018:0x01`, `0x1018sub1`, `6041h`, `1018h:01h`.
pub(crate) fn parse_object_ref(text: &str) -> Option<(u16, u8)> {
    let t = text.trim();
    let lower = t.to_ascii_lowercase();
    let (idx, sub) = if let Some((a, b)) = lower.split_once(':') {
        (a.to_string(), Some(b.to_string()))
    } else if let Some((a, b)) = lower.split_once("sub") {
        (a.to_string(), Some(b.to_string()))
    } else {
        (lower, None)
    };
    let index = parse_hexish(&idx, true)?;
    let sub = match sub {
        Some(s) => parse_hexish(&s, false)?,
        None => 0,
    };
    Some((u16::try_from(index).ok()?, u8::try_from(sub).ok()?))
}

/// `0x..` or `..h` is hex; for indices bare digits are hex too (CANopen habit), for subs decimal.
fn parse_hexish(t: &str, bare_is_hex: bool) -> Option<u32> {
    let t = t.trim();
    if let Some(h) = t.strip_prefix("0x") {
        return u32::from_str_radix(h, 16).ok();
    }
    if let Some(h) = t.strip_suffix('h') {
        return u32::from_str_radix(h, 16).ok();
    }
    if t.is_empty() || !t.chars().all(|c| c.is_ascii_hexdigit()) {
        return None;
    }
    if bare_is_hex {
        (t.len() == 4).then(|| u32::from_str_radix(t, 16).ok())?
    } else {
        t.parse().ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule(p: &str, index: &str, sub: &str) -> AliasRule {
        AliasRule::new(p, Expr::parse(index).unwrap(), Expr::parse(sub).unwrap(), None).unwrap()
    }

    #[test]
    fn syntron_and_aimotor_rules() {
        let f = rule("F{x:hex}.{y:hex}.{z:hex}", "0x2000 + 0x1000*x + 0x100*y + z", "0");
        assert_eq!(f.apply("F1.3.018"), Some((0x3318, 0)));
        assert_eq!(f.apply("f0.1.002"), Some((0x2102, 0)));
        assert_eq!(f.apply("F0.1"), None);
        assert_eq!(f.apply("F0.1.002x"), None);
        let pn = rule("Pn{y:hex}.{z:hex}", "0x4000 + 0x100*y + z", "0");
        assert_eq!(pn.apply("Pn5.00A"), Some((0x450A, 0)));
        let h = rule("H{xx:hex}-{yy}", "0x2000 + xx", "yy + 1");
        assert_eq!(h.apply("H12-20"), Some((0x2012, 21)));
        assert_eq!(h.apply("H03-09"), Some((0x2003, 10)));
        assert_eq!(h.apply("H03-0A"), None);
    }

    #[test]
    fn out_of_range_results_do_not_match() {
        let r = rule("R{n}", "n", "0");
        assert_eq!(r.apply("R65535"), Some((0xFFFF, 0)));
        assert_eq!(r.apply("R65536"), None);
        assert_eq!(r.apply("R99999999999999999999"), None);
    }

    #[test]
    fn bad_rules_are_errors() {
        let e = |p: &str, i: &str| AliasRule::new(p, Expr::parse(i).unwrap(), Expr::constant(0), None);
        assert!(e("F{x}{y}", "x").unwrap_err().to_string().contains("separator"));
        assert!(e("F{x:oct}", "x").unwrap_err().to_string().contains("oct"));
        assert!(e("F{x}", "x + q").unwrap_err().to_string().contains("`q`"));
        assert!(e("F", "1").unwrap_err().to_string().contains("no placeholder"));
    }

    #[test]
    fn index_forms() {
        assert_eq!(parse_object_ref("0x6041"), Some((0x6041, 0)));
        assert_eq!(parse_object_ref("0x1018:1"), Some((0x1018, 1)));
        assert_eq!(parse_object_ref("0x1018:0x0A"), Some((0x1018, 10)));
        assert_eq!(parse_object_ref("1018sub1"), Some((0x1018, 1)));
        assert_eq!(parse_object_ref("6041h"), Some((0x6041, 0)));
        assert_eq!(parse_object_ref("6041"), Some((0x6041, 0)));
        assert_eq!(parse_object_ref("0x10000"), None);
        assert_eq!(parse_object_ref("0x1018:256"), None);
        assert_eq!(parse_object_ref("09-26"), None);
        assert_eq!(parse_object_ref("statusword"), None);
    }
}
