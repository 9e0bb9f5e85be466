//! Tokens of the filter language, each with its 1-based column.

use super::error::FilterError;

/// A comparison operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cmp {
    /// `==` or `=`.
    Eq,
    /// `!=`.
    Ne,
    /// `<`.
    Lt,
    /// `<=`.
    Le,
    /// `>`.
    Gt,
    /// `>=`.
    Ge,
}

impl Cmp {
    /// True when `a op b`.
    pub fn holds(self, a: f64, b: f64) -> bool {
        match self {
            Cmp::Eq => a == b,
            Cmp::Ne => a != b,
            Cmp::Lt => a < b,
            Cmp::Le => a <= b,
            Cmp::Gt => a > b,
            Cmp::Ge => a >= b,
        }
    }
}

/// What a token is.
#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    /// `(`.
    Open,
    /// `)`.
    Close,
    /// `!` (not followed by `=`).
    Bang,
    /// `&`: a bit mask test.
    Amp,
    /// A comparison operator.
    Cmp(Cmp),
    /// `"text"`, without the quotes.
    Quoted(String),
    /// Anything else up to a space or one of `()"!<>=&`.
    Word(String),
}

/// A token and where it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Token {
    /// What it is.
    pub tok: Tok,
    /// 1-based column (in characters) of its first character.
    pub column: usize,
    /// Its length in characters as typed.
    pub width: usize,
}

impl Token {
    /// The column just after the token.
    pub fn end(&self) -> usize {
        self.column + self.width
    }
}

fn special(c: char) -> bool {
    matches!(c, '(' | ')' | '"' | '!' | '<' | '>' | '=' | '&')
}

/// Splits `text` into tokens; an unterminated quote is an error at its column.
pub fn tokens(text: &str) -> Result<Vec<Token>, FilterError> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let column = i + 1;
        let next = chars.get(i + 1).copied();
        let (tok, width) = match c {
            _ if c.is_whitespace() => {
                i += 1;
                continue;
            }
            '(' => (Tok::Open, 1),
            ')' => (Tok::Close, 1),
            '&' => (Tok::Amp, 1),
            '!' if next == Some('=') => (Tok::Cmp(Cmp::Ne), 2),
            '!' => (Tok::Bang, 1),
            '=' if next == Some('=') => (Tok::Cmp(Cmp::Eq), 2),
            '=' => (Tok::Cmp(Cmp::Eq), 1),
            '<' if next == Some('=') => (Tok::Cmp(Cmp::Le), 2),
            '<' => (Tok::Cmp(Cmp::Lt), 1),
            '>' if next == Some('=') => (Tok::Cmp(Cmp::Ge), 2),
            '>' => (Tok::Cmp(Cmp::Gt), 1),
            '"' => {
                let Some(len) = chars[i + 1..].iter().position(|&c| c == '"') else {
                    return Err(FilterError::new(column, "unterminated quote"));
                };
                let s: String = chars[i + 1..i + 1 + len].iter().collect();
                (Tok::Quoted(s), len + 2)
            }
            _ => {
                let len = chars[i..]
                    .iter()
                    .position(|&c| c.is_whitespace() || special(c))
                    .unwrap_or(chars.len() - i);
                (Tok::Word(chars[i..i + len].iter().collect()), len)
            }
        };
        out.push(Token { tok, column, width });
        i += width;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toks(s: &str) -> Vec<(Tok, usize)> {
        tokens(s).unwrap().into_iter().map(|t| (t.tok, t.column)).collect()
    }

    #[test]
    fn operators_words_quotes_and_columns() {
        assert_eq!(
            toks("!(node=3)&x!=\"a b\" >=-5"),
            [
                (Tok::Bang, 1),
                (Tok::Open, 2),
                (Tok::Word("node".into()), 3),
                (Tok::Cmp(Cmp::Eq), 7),
                (Tok::Word("3".into()), 8),
                (Tok::Close, 9),
                (Tok::Amp, 10),
                (Tok::Word("x".into()), 11),
                (Tok::Cmp(Cmp::Ne), 12),
                (Tok::Quoted("a b".into()), 14),
                (Tok::Cmp(Cmp::Ge), 20),
                (Tok::Word("-5".into()), 22),
            ]
        );
        assert_eq!(
            toks("id 700-77f 6041:00"),
            [
                (Tok::Word("id".into()), 1),
                (Tok::Word("700-77f".into()), 4),
                (Tok::Word("6041:00".into()), 12),
            ]
        );
        assert_eq!(tokens("a \"open").unwrap_err().column, 3);
        // Columns count characters, not bytes.
        assert_eq!(toks("\"µs\" x")[1], (Tok::Word("x".into()), 6));
    }
}
