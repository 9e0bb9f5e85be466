//! Named procedures from profiles: command sequences such as "enable and run
//! in profile velocity mode", as data for the commander to execute.

use super::expr::{Expr, ExprError};
use super::value::DataType;

/// What is wrong with a procedure step in a profile.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ProcedureError {
    #[error("missing `}}` in object `{0}`")]
    ObjectBrace(String),
    #[error("missing `}}` in `{0}`")]
    DataBrace(String),
    #[error("bad field type `{ty}` in `{text}`")]
    FieldType { ty: String, text: String },
    #[error("`{token}` is not a byte (two hex digits) in `{text}`")]
    NotAByte { token: String, text: String },
    #[error("`{token}` is not a hex byte in `{text}`")]
    NotHex { token: String, text: String },
    #[error("frame data `{text}` is {len} bytes, at most 8")]
    TooLong { text: String, len: usize },
    #[error("object `{object}` uses unknown variable `{variable}`")]
    ObjectVariable { object: String, variable: String },
    #[error("`{expr}` uses unknown variable `{variable}`")]
    Variable { expr: String, variable: String },
    #[error(transparent)]
    Expr(#[from] ExprError),
}

/// A parameter of a procedure (`speed`, `position`); `node` always exists.
#[derive(Clone, Debug, PartialEq)]
pub struct ProcParam {
    /// Variable name used in the steps' expressions.
    pub name: String,
    /// Unit, for the help text.
    pub unit: Option<String>,
    /// Help text.
    pub description: Option<String>,
    /// Value when not given; `None` makes the parameter required.
    pub default: Option<i64>,
}

/// NMT commands a procedure can send.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NmtCommand {
    Start,
    Stop,
    PreOperational,
    Reset,
    ResetCommunication,
}

impl NmtCommand {
    /// The NMT command specifier (byte 0 of the 0x000 frame).
    pub fn specifier(self) -> u8 {
        match self {
            NmtCommand::Start => 0x01,
            NmtCommand::Stop => 0x02,
            NmtCommand::PreOperational => 0x80,
            NmtCommand::Reset => 0x81,
            NmtCommand::ResetCommunication => 0x82,
        }
    }

    /// Parses `start`, `stop`, `pre-operational`, `reset`, `reset-communication`.
    pub fn parse(text: &str) -> Option<NmtCommand> {
        Some(match text.trim().to_ascii_lowercase().replace('_', "-").as_str() {
            "start" => NmtCommand::Start,
            "stop" => NmtCommand::Stop,
            "pre-operational" | "preoperational" => NmtCommand::PreOperational,
            "reset" | "reset-node" => NmtCommand::Reset,
            "reset-communication" | "reset-comm" => NmtCommand::ResetCommunication,
            _ => return None,
        })
    }
}

/// One byte-level item of a raw frame's data.
#[derive(Clone, Debug, PartialEq)]
pub enum FrameItem {
    /// A fixed byte.
    Byte(u8),
    /// A little-endian value of this type (`u8`..`i32`) from an expression.
    Value(DataType, Expr),
}

/// Splits an object text into literal pieces and `{EXPR}` placeholders
/// (`"{page}-{number}"`, `"0x3000:{sub}"`).
fn object_pieces(text: &str) -> Result<Vec<Result<&str, Expr>>, ProcedureError> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(open) = rest.find('{') {
        out.push(Ok(&rest[..open]));
        let after = &rest[open + 1..];
        let end = after
            .find('}')
            .ok_or_else(|| ProcedureError::ObjectBrace(text.to_string()))?;
        out.push(Err(Expr::parse(&after[..end])?));
        rest = &after[end + 1..];
    }
    out.push(Ok(rest));
    Ok(out)
}

/// Checks the `{EXPR}` placeholders of a step's object text; gives the variables they use.
pub(crate) fn object_variables(text: &str) -> Result<Vec<String>, ProcedureError> {
    Ok(object_pieces(text)?
        .into_iter()
        .filter_map(Result::err)
        .flat_map(|e| e.variables().into_iter().map(str::to_string).collect::<Vec<_>>())
        .collect())
}

/// A step's object text with each `{EXPR}` replaced by its value in decimal, e.g.
/// `"{page}-{number}"` with page 3, number 1 gives `"3-1"` (then resolved like typed text).
pub fn fill_object(text: &str, vars: &dyn Fn(&str) -> Option<i64>) -> Result<String, ProcedureError> {
    let mut out = String::new();
    for piece in object_pieces(text)? {
        match piece {
            Ok(literal) => out.push_str(literal),
            Err(e) => out.push_str(&e.eval(vars)?.to_string()),
        }
    }
    Ok(out)
}

/// One step of a procedure.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// Write `value` to an object (text as typed: index, alias or name; `{EXPR}` in it is
    /// replaced by the value, see [`fill_object`]).
    SdoWrite {
        object: String,
        value: Expr,
        data_type: Option<DataType>,
    },
    /// Read an object.
    SdoRead { object: String },
    /// Send an NMT command to `node` (the target node when `None`; 0 = all).
    Nmt { command: NmtCommand, node: Option<Expr> },
    /// Wait until `(object & mask) == equals`, at most `timeout_ms`; fail at once when
    /// `fail_if` matches (e.g. statusword bit 13 "homing error").
    Wait {
        object: String,
        mask: Expr,
        equals: Expr,
        timeout_ms: u32,
        fail_if: Option<FailIf>,
    },
    /// Send a raw frame.
    Frame { id: Expr, data: Vec<FrameItem> },
    /// Pause.
    Delay { ms: u32 },
}

/// When a `wait` step gives up early: `(value & mask) == equals` means `text`.
#[derive(Clone, Debug, PartialEq)]
pub struct FailIf {
    /// Bits compared.
    pub mask: Expr,
    /// Their failing value.
    pub equals: Expr,
    /// What it means, e.g. `homing error`.
    pub text: String,
}

/// A named command sequence.
#[derive(Clone, Debug, PartialEq)]
pub struct Procedure {
    /// Name used on the command line, e.g. `pv`.
    pub name: String,
    /// Help text.
    pub description: Option<String>,
    /// Parameters besides `node`.
    pub params: Vec<ProcParam>,
    /// The steps, in order.
    pub steps: Vec<Step>,
}

impl FrameItem {
    /// Size in bytes.
    pub fn size(&self) -> usize {
        match self {
            FrameItem::Byte(_) => 1,
            FrameItem::Value(t, _) => t.size().unwrap_or(0),
        }
    }
}

/// Parses frame data: `2B 40 60 00 {u16:ctrl} 00 00`; at most 8 bytes.
pub fn parse_frame_data(text: &str) -> Result<Vec<FrameItem>, ProcedureError> {
    let mut items = Vec::new();
    let mut rest = text.trim();
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix('{') {
            let end = after
                .find('}')
                .ok_or_else(|| ProcedureError::DataBrace(text.to_string()))?;
            let inner = &after[..end];
            let (ty, expr) = match inner.split_once(':') {
                Some((t, e)) => (
                    int_type(t.trim()).ok_or_else(|| ProcedureError::FieldType {
                        ty: t.to_string(),
                        text: text.to_string(),
                    })?,
                    e,
                ),
                None => (DataType::U8, inner),
            };
            items.push(FrameItem::Value(ty, Expr::parse(expr)?));
            rest = after[end + 1..].trim_start();
        } else {
            let end = rest.find(char::is_whitespace).unwrap_or(rest.len());
            let tok = &rest[..end];
            if tok.len() != 2 {
                return Err(ProcedureError::NotAByte {
                    token: tok.to_string(),
                    text: text.to_string(),
                });
            }
            items.push(FrameItem::Byte(u8::from_str_radix(tok, 16).map_err(|_| {
                ProcedureError::NotHex {
                    token: tok.to_string(),
                    text: text.to_string(),
                }
            })?));
            rest = rest[end..].trim_start();
        }
    }
    let len: usize = items.iter().map(FrameItem::size).sum();
    if len > 8 {
        return Err(ProcedureError::TooLong {
            text: text.to_string(),
            len,
        });
    }
    Ok(items)
}

fn int_type(t: &str) -> Option<DataType> {
    Some(match t {
        "u8" => DataType::U8,
        "i8" => DataType::I8,
        "u16" => DataType::U16,
        "i16" => DataType::I16,
        "u24" => DataType::U24,
        "i24" => DataType::I24,
        "u32" => DataType::U32,
        "i32" => DataType::I32,
        _ => return None,
    })
}

impl Procedure {
    /// Every variable a step uses must be `node` or a parameter.
    pub fn check_variables(&self) -> Result<(), ProcedureError> {
        let known = |v: &str| v == "node" || self.params.iter().any(|p| p.name == v);
        let mut exprs: Vec<&Expr> = Vec::new();
        for s in &self.steps {
            if let Step::SdoWrite { object, .. } | Step::SdoRead { object } | Step::Wait { object, .. } = s
                && let Some(v) = object_variables(object)?.into_iter().find(|v| !known(v))
            {
                return Err(ProcedureError::ObjectVariable {
                    object: object.clone(),
                    variable: v,
                });
            }
            match s {
                Step::SdoWrite { value, .. } => exprs.push(value),
                Step::Nmt { node: Some(n), .. } => exprs.push(n),
                Step::Wait {
                    mask, equals, fail_if, ..
                } => {
                    exprs.extend([mask, equals]);
                    if let Some(f) = fail_if {
                        exprs.extend([&f.mask, &f.equals]);
                    }
                }
                Step::Frame { id, data } => {
                    exprs.push(id);
                    exprs.extend(data.iter().filter_map(|i| match i {
                        FrameItem::Value(_, e) => Some(e),
                        FrameItem::Byte(_) => None,
                    }));
                }
                _ => {}
            }
        }
        for e in exprs {
            if let Some(v) = e.variables().into_iter().find(|v| !known(v)) {
                return Err(ProcedureError::Variable {
                    expr: e.to_string(),
                    variable: v.to_string(),
                });
            }
        }
        Ok(())
    }
}

/// Builds the bytes of a `Frame` step's data with the given variables.
pub fn frame_bytes(items: &[FrameItem], vars: &dyn Fn(&str) -> Option<i64>) -> Result<Vec<u8>, ExprError> {
    let mut out = Vec::new();
    for item in items {
        match item {
            FrameItem::Byte(b) => out.push(*b),
            FrameItem::Value(t, e) => {
                let v = e.eval(vars)?;
                let n = t.size().unwrap_or(0);
                out.extend_from_slice(&v.to_le_bytes()[..n]);
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_data_template() {
        let items = parse_frame_data("2B 40 60 00 {u16:ctrl} 00 00").unwrap();
        let bytes = frame_bytes(&items, &|v| (v == "ctrl").then_some(0x0F)).unwrap();
        assert_eq!(bytes, vec![0x2B, 0x40, 0x60, 0x00, 0x0F, 0x00, 0x00, 0x00]);
        let items = parse_frame_data("23 7A 60 00 {i32:-position}").unwrap();
        let bytes = frame_bytes(&items, &|_| Some(1)).unwrap();
        assert_eq!(bytes, vec![0x23, 0x7A, 0x60, 0x00, 0xFF, 0xFF, 0xFF, 0xFF]);
    }

    #[test]
    fn bad_frame_data_is_an_error() {
        assert!(
            parse_frame_data("2B 40 60 00 {u32:1} 00")
                .unwrap_err()
                .to_string()
                .contains("at most 8")
        );
        assert!(parse_frame_data("2B4").is_err());
        assert!(parse_frame_data("GG").is_err());
        assert!(parse_frame_data("{f32:1}").unwrap_err().to_string().contains("f32"));
        assert!(parse_frame_data("{u8:1").is_err());
    }

    #[test]
    fn nmt_names() {
        assert_eq!(
            NmtCommand::parse("Pre-Operational").map(NmtCommand::specifier),
            Some(0x80)
        );
        assert_eq!(
            NmtCommand::parse("reset_communication"),
            Some(NmtCommand::ResetCommunication)
        );
        assert_eq!(NmtCommand::parse("go"), None);
    }

    #[test]
    fn object_placeholders() {
        let vars = |v: &str| match v {
            "page" => Some(3),
            "number" => Some(1),
            _ => None,
        };
        assert_eq!(fill_object("{page}-{number}", &vars).unwrap(), "3-1");
        assert_eq!(fill_object("0x3000:{number + 9}", &vars).unwrap(), "0x3000:10");
        assert_eq!(fill_object("0x6041", &vars).unwrap(), "0x6041");
        assert_eq!(object_variables("{page}-{number}").unwrap(), ["page", "number"]);
        assert!(
            object_variables("0x3000:{sub")
                .unwrap_err()
                .to_string()
                .contains("missing `}`")
        );
        assert!(fill_object("{speed}", &vars).is_err());
    }
}
