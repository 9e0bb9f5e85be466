//! Byte fields inside frames described by profiles: the manufacturer-specific
//! bytes of an EMCY and vendor SDO commands (e.g. Syn-tron 0xE8/0xE9).

use std::collections::BTreeMap;

use super::expr::Expr;

/// A little-endian integer field at a fixed place in a frame's data.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ByteField {
    /// Label, e.g. "M1 alarm code".
    pub name: String,
    /// 0-based byte offset in the frame data.
    pub offset: u8,
    /// Length in bytes (1..=4).
    pub length: u8,
    /// Two's-complement signed.
    pub signed: bool,
    /// Show the raw value in hex.
    pub hex: bool,
    /// The value is an EMCY error code (`"format": "emcy"`): shown in hex with the code's
    /// text from the node's dictionary (fields of object values only).
    pub emcy: bool,
    /// Texts for raw values.
    pub values: BTreeMap<i64, String>,
    /// Unit of raw * scale.
    pub unit: Option<String>,
    /// Physical value = raw * scale.
    pub scale: Option<f64>,
    /// The object index this value belongs to, from earlier fields (vendor SDO commands).
    pub object: Option<Expr>,
    /// The object sub-index, from earlier fields (0 when absent).
    pub object_sub: Option<Expr>,
}

impl ByteField {
    /// The raw value, or `None` when the data is too short.
    pub fn raw(&self, data: &[u8]) -> Option<i64> {
        let start = self.offset as usize;
        let bytes = data.get(start..start + self.length as usize)?;
        let mut v: u64 = 0;
        for (i, b) in bytes.iter().enumerate() {
            v |= (*b as u64) << (8 * i);
        }
        if self.signed && !bytes.is_empty() {
            let shift = 64 - 8 * bytes.len() as u32;
            Some(((v << shift) as i64) >> shift)
        } else {
            Some(v as i64)
        }
    }

    /// The value as shown: value text, scaled value with unit, or raw (hex when asked).
    pub fn format(&self, raw: i64) -> String {
        let base = if self.hex {
            format!(
                "0x{:0width$X}",
                raw as u64 & mask(self.length),
                width = 2 * self.length as usize
            )
        } else if self.scale.is_some() || self.unit.is_some() {
            let mut s = super::number::format_number(raw as f64 * self.scale.unwrap_or(1.0));
            if let Some(u) = &self.unit {
                s.push(' ');
                s.push_str(u);
            }
            s
        } else {
            raw.to_string()
        };
        match self.values.get(&raw) {
            Some(text) => format!("{base} ({text})"),
            None => base,
        }
    }
}

fn mask(len: u8) -> u64 {
    if len >= 8 {
        u64::MAX
    } else {
        (1u64 << (8 * len as u32)) - 1
    }
}

/// Which way a vendor SDO command travels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SdoDirection {
    /// Client to server (0x600 + node).
    Request,
    /// Server to client (0x580 + node).
    Response,
}

/// A non-standard SDO command byte and the layout of its frame.
#[derive(Clone, Debug, PartialEq)]
pub struct SdoCommand {
    /// Byte 0 of the SDO frame.
    pub command: u8,
    /// Which way it travels.
    pub direction: SdoDirection,
    /// Label, e.g. "Read axis A and B".
    pub name: String,
    /// The fields of the frame.
    pub fields: Vec<ByteField>,
}

/// One decoded field of a vendor SDO frame.
#[derive(Clone, Debug, PartialEq)]
pub struct DecodedField {
    /// The field's name.
    pub name: String,
    /// The raw value.
    pub raw: i64,
    /// The object this value belongs to, when the field says so.
    pub object: Option<(u16, u8)>,
}

impl SdoCommand {
    /// Decodes the frame data field by field; fields past the data end are left out.
    pub fn decode(&self, data: &[u8]) -> Vec<DecodedField> {
        let mut out: Vec<DecodedField> = Vec::new();
        for f in &self.fields {
            let Some(raw) = f.raw(data) else { continue };
            let object = f.object.as_ref().and_then(|e| {
                let lookup = |n: &str| out.iter().find(|d| d.name == n).map(|d| d.raw);
                let index = u16::try_from(e.eval(&lookup).ok()?).ok()?;
                let sub = match &f.object_sub {
                    Some(s) => u8::try_from(s.eval(&lookup).ok()?).ok()?,
                    None => 0,
                };
                Some((index, sub))
            });
            out.push(DecodedField {
                name: f.name.clone(),
                raw,
                object,
            });
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(name: &str, offset: u8, length: u8) -> ByteField {
        ByteField {
            name: name.into(),
            offset,
            length,
            ..Default::default()
        }
    }

    #[test]
    fn syntron_e8_response_gives_both_axes() {
        let mut a = field("A", 4, 2);
        a.signed = true;
        a.object = Some(Expr::parse("index").unwrap());
        a.object_sub = Some(Expr::parse("sub").unwrap());
        let mut b = field("B", 6, 2);
        b.signed = true;
        b.object = Some(Expr::parse("index + (index >= 0x5000 ? 0x100 : 0x1000)").unwrap());
        let cmd = SdoCommand {
            command: 0xE8,
            direction: SdoDirection::Response,
            name: "Axis A and B values".into(),
            fields: vec![field("index", 1, 2), field("sub", 3, 1), a, b],
        };
        let d = cmd.decode(&[0xE8, 0x04, 0x50, 0x00, 0xB7, 0x13, 0xAB, 0x12]);
        assert_eq!(
            d[2],
            DecodedField {
                name: "A".into(),
                raw: 5047,
                object: Some((0x5004, 0))
            }
        );
        assert_eq!(
            d[3],
            DecodedField {
                name: "B".into(),
                raw: 4779,
                object: Some((0x5104, 0))
            }
        );
        let d = cmd.decode(&[0xE9, 0x18, 0x23, 0x00, 0x36, 0x00, 0xCA, 0xFF]);
        assert_eq!((d[2].raw, d[2].object), (54, Some((0x2318, 0))));
        assert_eq!((d[3].raw, d[3].object), (-54, Some((0x3318, 0))));
        assert_eq!(cmd.decode(&[0xE8, 0x04]).len(), 0);
    }

    #[test]
    fn formats_texts_hex_and_units() {
        let mut f = field("M1 alarm code", 6, 1);
        f.values.insert(1, "Over-current".into());
        assert_eq!(f.format(f.raw(&[0, 0, 0, 0, 0, 0, 1, 0]).unwrap()), "1 (Over-current)");
        f.hex = true;
        assert_eq!(f.format(1), "0x01 (Over-current)");
        let mut v = field("Voltage", 3, 2);
        v.scale = Some(0.1);
        v.unit = Some("V".into());
        assert_eq!(v.format(245), "24.5 V");
        assert_eq!(v.raw(&[0, 0, 0, 0xF5]), None);
    }
}
