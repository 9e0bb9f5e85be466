//! Integer expressions used in profiles: alias rules, COB-IDs, procedure values.
//!
//! `0x2000 + 0x1000*x + 0x100*y + z`, `index >= 0x5000 ? 0x100 : 0x1000`,
//! `speed * 10`. C precedence, 64-bit signed arithmetic, no panics: overflow,
//! division by zero and unknown variables are evaluation errors.

use std::fmt;

/// What is wrong with an expression: its text (parsing) or its value (evaluating).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ExprError {
    /// A character no token starts with (`at` counts from 1).
    #[error("unexpected `{ch}` at character {at} of expression `{text}`")]
    BadCharacter { ch: char, at: usize, text: String },
    #[error("bad number `{literal}` in expression `{text}`")]
    BadNumber { literal: String, text: String },
    /// A token after a complete expression.
    #[error("unexpected {token} in expression `{text}`")]
    Trailing { token: String, text: String },
    /// A token where an operand belongs.
    #[error("unexpected {0}")]
    Unexpected(String),
    #[error("expected `:` after `?` branch")]
    ExpectedColon,
    #[error("missing `)`")]
    MissingClose,
    #[error("expression ends too early")]
    EndsEarly,
    #[error("expression nests deeper than {MAX_DEPTH} levels (parentheses, unary operators, `?:` or operator chains)")]
    TooDeep,
    /// Evaluating the expression `expr` failed.
    #[error("{fault} in `{expr}`")]
    Eval { fault: EvalFault, expr: String },
}

/// Why evaluating an expression failed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum EvalFault {
    #[error("unknown variable `{0}`")]
    UnknownVariable(String),
    #[error("arithmetic overflow")]
    Overflow,
    #[error("bad shift {0}")]
    BadShift(i64),
    #[error("division by zero")]
    DivisionByZero,
}

/// A parsed expression, keeping its source text for messages.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    src: String,
    node: Node,
}

#[derive(Clone, Debug, PartialEq)]
enum Node {
    Num(i64),
    Var(String),
    Unary(char, Box<Node>),
    Binary(Op, Box<Node>, Box<Node>),
    Cond(Box<Node>, Box<Node>, Box<Node>),
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Op {
    Mul,
    Div,
    Rem,
    Add,
    Sub,
    Shl,
    Shr,
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
    BitAnd,
    BitXor,
    BitOr,
    And,
    Or,
}

impl Op {
    /// Binding power (higher binds tighter), as in C.
    fn power(self) -> u8 {
        use Op::*;
        match self {
            Mul | Div | Rem => 10,
            Add | Sub => 9,
            Shl | Shr => 8,
            Lt | Le | Gt | Ge => 7,
            Eq | Ne => 6,
            BitAnd => 5,
            BitXor => 4,
            BitOr => 3,
            And => 2,
            Or => 1,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(i64),
    Ident(String),
    Op(Op),
    Not,
    Tilde,
    Question,
    Colon,
    Open,
    Close,
}

impl Expr {
    /// Parses `text`; the error says what is wrong and at which character.
    pub fn parse(text: &str) -> Result<Expr, ExprError> {
        let toks = tokenize(text)?;
        let mut p = Parser {
            toks: &toks,
            pos: 0,
            depth: 0,
        };
        let (node, _) = p.conditional()?;
        if p.pos < toks.len() {
            return Err(ExprError::Trailing {
                token: format!("{:?}", toks[p.pos]),
                text: text.to_string(),
            });
        }
        Ok(Expr {
            src: text.trim().to_string(),
            node,
        })
    }

    /// A constant expression.
    pub fn constant(value: i64) -> Expr {
        Expr {
            src: value.to_string(),
            node: Node::Num(value),
        }
    }

    /// Names of the variables the expression uses, in order of first use.
    pub fn variables(&self) -> Vec<&str> {
        fn walk<'a>(n: &'a Node, out: &mut Vec<&'a str>) {
            match n {
                Node::Num(_) => {}
                Node::Var(v) => {
                    if !out.contains(&v.as_str()) {
                        out.push(v);
                    }
                }
                Node::Unary(_, a) => walk(a, out),
                Node::Binary(_, a, b) => {
                    walk(a, out);
                    walk(b, out);
                }
                Node::Cond(c, a, b) => {
                    walk(c, out);
                    walk(a, out);
                    walk(b, out);
                }
            }
        }
        let mut out = Vec::new();
        walk(&self.node, &mut out);
        out
    }

    /// Evaluates with `vars` giving each variable's value.
    pub fn eval(&self, vars: &dyn Fn(&str) -> Option<i64>) -> Result<i64, ExprError> {
        eval(&self.node, vars).map_err(|fault| ExprError::Eval {
            fault,
            expr: self.src.clone(),
        })
    }
}

impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.src)
    }
}

fn eval(n: &Node, vars: &dyn Fn(&str) -> Option<i64>) -> Result<i64, EvalFault> {
    let overflow = || EvalFault::Overflow;
    Ok(match n {
        Node::Num(v) => *v,
        Node::Var(name) => vars(name).ok_or_else(|| EvalFault::UnknownVariable(name.clone()))?,
        Node::Unary(op, a) => {
            let a = eval(a, vars)?;
            match op {
                '-' => a.checked_neg().ok_or_else(overflow)?,
                '!' => (a == 0) as i64,
                _ => !a,
            }
        }
        Node::Cond(c, a, b) => {
            if eval(c, vars)? != 0 {
                eval(a, vars)?
            } else {
                eval(b, vars)?
            }
        }
        Node::Binary(op, a, b) => {
            let x = eval(a, vars)?;
            // Short-circuit the logical operators.
            match op {
                Op::And if x == 0 => return Ok(0),
                Op::Or if x != 0 => return Ok(1),
                _ => {}
            }
            let y = eval(b, vars)?;
            let shift = |y: i64| u32::try_from(y).ok().filter(|s| *s < 64).ok_or(EvalFault::BadShift(y));
            match op {
                Op::Mul => x.checked_mul(y).ok_or_else(overflow)?,
                Op::Div => x.checked_div(y).ok_or(EvalFault::DivisionByZero)?,
                Op::Rem => x.checked_rem(y).ok_or(EvalFault::DivisionByZero)?,
                Op::Add => x.checked_add(y).ok_or_else(overflow)?,
                Op::Sub => x.checked_sub(y).ok_or_else(overflow)?,
                Op::Shl => x.checked_shl(shift(y)?).ok_or_else(overflow)?,
                Op::Shr => x >> shift(y)?,
                Op::Lt => (x < y) as i64,
                Op::Le => (x <= y) as i64,
                Op::Gt => (x > y) as i64,
                Op::Ge => (x >= y) as i64,
                Op::Eq => (x == y) as i64,
                Op::Ne => (x != y) as i64,
                Op::BitAnd => x & y,
                Op::BitXor => x ^ y,
                Op::BitOr => x | y,
                Op::And | Op::Or => (y != 0) as i64,
            }
        }
    })
}

fn tokenize(text: &str) -> Result<Vec<Tok>, ExprError> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        if c.is_ascii_digit() {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            let lit: String = chars[start..i].iter().collect();
            let v = parse_int(&lit).ok_or_else(|| ExprError::BadNumber {
                literal: lit.clone(),
                text: text.to_string(),
            })?;
            out.push(Tok::Num(v));
            continue;
        }
        if c.is_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push(Tok::Ident(chars[start..i].iter().collect()));
            continue;
        }
        let next = chars.get(i + 1).copied();
        let (tok, len) = match (c, next) {
            ('<', Some('<')) => (Tok::Op(Op::Shl), 2),
            ('>', Some('>')) => (Tok::Op(Op::Shr), 2),
            ('<', Some('=')) => (Tok::Op(Op::Le), 2),
            ('>', Some('=')) => (Tok::Op(Op::Ge), 2),
            ('=', Some('=')) => (Tok::Op(Op::Eq), 2),
            ('!', Some('=')) => (Tok::Op(Op::Ne), 2),
            ('&', Some('&')) => (Tok::Op(Op::And), 2),
            ('|', Some('|')) => (Tok::Op(Op::Or), 2),
            ('<', _) => (Tok::Op(Op::Lt), 1),
            ('>', _) => (Tok::Op(Op::Gt), 1),
            ('*', _) => (Tok::Op(Op::Mul), 1),
            ('/', _) => (Tok::Op(Op::Div), 1),
            ('%', _) => (Tok::Op(Op::Rem), 1),
            ('+', _) => (Tok::Op(Op::Add), 1),
            ('-', _) => (Tok::Op(Op::Sub), 1),
            ('&', _) => (Tok::Op(Op::BitAnd), 1),
            ('^', _) => (Tok::Op(Op::BitXor), 1),
            ('|', _) => (Tok::Op(Op::BitOr), 1),
            ('!', _) => (Tok::Not, 1),
            ('~', _) => (Tok::Tilde, 1),
            ('?', _) => (Tok::Question, 1),
            (':', _) => (Tok::Colon, 1),
            ('(', _) => (Tok::Open, 1),
            (')', _) => (Tok::Close, 1),
            _ => {
                return Err(ExprError::BadCharacter {
                    ch: c,
                    at: i + 1,
                    text: text.to_string(),
                });
            }
        };
        out.push(tok);
        i += len;
    }
    Ok(out)
}

/// Parses `0x1A`, `0b101`, `-12` or `42` (no octal here: `018` is decimal 18).
pub fn parse_int(text: &str) -> Option<i64> {
    let t = text.trim();
    let (neg, t) = match t.strip_prefix('-') {
        Some(rest) => (true, rest.trim_start()),
        None => (false, t),
    };
    let t = t.replace('_', "");
    let v = if let Some(h) = t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        u64::from_str_radix(h, 16).ok()?
    } else if let Some(b) = t.strip_prefix("0b").or_else(|| t.strip_prefix("0B")) {
        u64::from_str_radix(b, 2).ok()?
    } else {
        t.parse::<u64>().ok()?
    };
    if neg {
        0i64.checked_sub_unsigned(v)
    } else {
        // Values up to u64::MAX are kept as their two's-complement bit pattern.
        Some(v as i64)
    }
}

/// How deep an expression may nest: parentheses, unary operators, `?:` branches and
/// operator chains each count one level. Profiles need a handful; the limit keeps parsing,
/// evaluating and dropping far from the end of the stack.
pub const MAX_DEPTH: usize = 200;

struct Parser<'a> {
    toks: &'a [Tok],
    pos: usize,
    /// Levels of recursion now open.
    depth: usize,
}

/// A parsed node and its height (1 for a leaf).
type Parsed = (Node, usize);

impl Parser<'_> {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.pos)
    }

    /// Opens one level of recursion; an error past [`MAX_DEPTH`].
    fn enter(&mut self) -> Result<(), ExprError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            Err(ExprError::TooDeep)
        } else {
            Ok(())
        }
    }

    fn conditional(&mut self) -> Result<Parsed, ExprError> {
        self.enter()?;
        let (c, hc) = self.binary(0)?;
        let out = if self.peek() == Some(&Tok::Question) {
            self.pos += 1;
            let (a, ha) = self.conditional()?;
            if self.peek() != Some(&Tok::Colon) {
                return Err(ExprError::ExpectedColon);
            }
            self.pos += 1;
            let (b, hb) = self.conditional()?;
            let h = hc.max(ha).max(hb) + 1;
            if h > MAX_DEPTH {
                return Err(ExprError::TooDeep);
            }
            (Node::Cond(Box::new(c), Box::new(a), Box::new(b)), h)
        } else {
            (c, hc)
        };
        self.depth -= 1;
        Ok(out)
    }

    fn binary(&mut self, min_power: u8) -> Result<Parsed, ExprError> {
        self.enter()?;
        let (mut left, mut height) = self.unary()?;
        while let Some(Tok::Op(op)) = self.peek() {
            let op = *op;
            if op.power() <= min_power {
                break;
            }
            self.pos += 1;
            let (right, hr) = self.binary(op.power())?;
            height = height.max(hr) + 1;
            if height > MAX_DEPTH {
                return Err(ExprError::TooDeep);
            }
            left = Node::Binary(op, Box::new(left), Box::new(right));
        }
        self.depth -= 1;
        Ok((left, height))
    }

    fn unary(&mut self) -> Result<Parsed, ExprError> {
        let op = match self.peek() {
            Some(Tok::Op(Op::Sub)) => '-',
            Some(Tok::Op(Op::Add)) => '+',
            Some(Tok::Not) => '!',
            Some(Tok::Tilde) => '~',
            _ => return self.primary(),
        };
        self.pos += 1;
        self.enter()?;
        let (inner, h) = self.unary()?;
        self.depth -= 1;
        Ok(if op == '+' {
            (inner, h)
        } else {
            (Node::Unary(op, Box::new(inner)), h + 1)
        })
    }

    fn primary(&mut self) -> Result<Parsed, ExprError> {
        let tok = self.peek().cloned();
        self.pos += 1;
        match tok {
            Some(Tok::Num(v)) => Ok((Node::Num(v), 1)),
            Some(Tok::Ident(name)) => Ok((Node::Var(name), 1)),
            Some(Tok::Open) => {
                let inner = self.conditional()?;
                if self.peek() != Some(&Tok::Close) {
                    return Err(ExprError::MissingClose);
                }
                self.pos += 1;
                Ok(inner)
            }
            Some(t) => Err(ExprError::Unexpected(format!("{t:?}"))),
            None => Err(ExprError::EndsEarly),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(text: &str, vars: &[(&str, i64)]) -> Result<i64, ExprError> {
        let e = Expr::parse(text)?;
        e.eval(&|n| vars.iter().find(|(k, _)| *k == n).map(|(_, v)| *v))
    }

    #[test]
    fn syntron_rule_and_precedence() {
        let vars = [("x", 1), ("y", 3), ("z", 0x18)];
        assert_eq!(ev("0x2000 + 0x1000*x + 0x100*y + z", &vars), Ok(0x3318));
        assert_eq!(ev("1 + 2 * 3 << 1", &[]), Ok(14));
        assert_eq!(ev("(1 + 2) * 3", &[]), Ok(9));
        assert_eq!(ev("-3 + ~0", &[]), Ok(-4));
        assert_eq!(ev("1 | 2 & 3 == 3", &[]), Ok(1));
    }

    #[test]
    fn conditional_and_comparisons() {
        let e = "index + (index >= 0x5000 ? 0x100 : 0x1000)";
        assert_eq!(ev(e, &[("index", 0x5004)]), Ok(0x5104));
        assert_eq!(ev(e, &[("index", 0x2318)]), Ok(0x3318));
        assert_eq!(ev("0 && 1/0", &[]), Ok(0));
        assert_eq!(ev("1 ? 2 : 0 ? 3 : 4", &[]), Ok(2));
    }

    #[test]
    fn errors_are_messages() {
        assert!(ev("1 / 0", &[]).unwrap_err().to_string().contains("division by zero"));
        assert!(
            ev("speed * 10", &[])
                .unwrap_err()
                .to_string()
                .contains("unknown variable `speed`")
        );
        assert!(
            ev("0x7FFFFFFFFFFFFFFF + 1", &[])
                .unwrap_err()
                .to_string()
                .contains("overflow")
        );
        assert!(Expr::parse("1 +").is_err());
        assert!(Expr::parse("(1").is_err());
        assert!(Expr::parse("2 $ 3").unwrap_err().to_string().contains("`$`"));
        assert!(Expr::parse("0xZZ").is_err());
        assert!(ev("1 << 64", &[]).is_err());
    }

    #[test]
    fn typed_errors_keep_their_messages() {
        let text = |r: Result<i64, ExprError>| r.unwrap_err().to_string();
        assert_eq!(
            text(ev("2 $ 3", &[])),
            "unexpected `$` at character 3 of expression `2 $ 3`"
        );
        assert_eq!(text(ev("0x1G", &[])), "bad number `0x1G` in expression `0x1G`");
        assert_eq!(text(ev("speed * 10", &[])), "unknown variable `speed` in `speed * 10`");
        assert_eq!(text(ev("1 << 64", &[])), "bad shift 64 in `1 << 64`");
        assert_eq!(text(ev("(1", &[])), "missing `)`");
        assert_eq!(
            ev("x / 0", &[("x", 1)]),
            Err(ExprError::Eval {
                fault: EvalFault::DivisionByZero,
                expr: "x / 0".into()
            })
        );
    }

    #[test]
    fn deep_nesting_is_an_error_not_a_stack_overflow() {
        let parens = format!("{}1{}", "(".repeat(20_000), ")".repeat(20_000));
        let minus = format!("{}1", "-".repeat(100_000));
        let nots = format!("{}1", "!~".repeat(50_000));
        let conds = format!("{}0", "1 ? 0 : ".repeat(20_000));
        let chain = format!("1{}", " + 1".repeat(100_000));
        for text in [&parens, &minus, &nots, &conds, &chain] {
            let e = Expr::parse(text).unwrap_err();
            assert!(e.to_string().contains("nests deeper than 200 levels"), "{e}");
        }
        // Reasonable nesting still parses.
        assert_eq!(ev(&format!("{}1{}", "(".repeat(50), ")".repeat(50)), &[]), Ok(1));
        assert_eq!(ev(&format!("{}1", "-".repeat(100)), &[]), Ok(1));
        assert_eq!(ev(&format!("{}7", "0 ? 1 : ".repeat(40)), &[]), Ok(7));
        assert_eq!(ev(&format!("0{}", " + 1".repeat(150)), &[]), Ok(150));
    }

    #[test]
    fn variables_in_order() {
        let e = Expr::parse("0x600 + node + node * speed").unwrap();
        assert_eq!(e.variables(), vec!["node", "speed"]);
    }
}
