//! Vendor SDO commands a profile describes (`sdo_commands`), e.g. the Syn-tron
//! 0xE8/0xE9 pair that reads or writes the same parameter of axes A and B in one frame.

use crate::od::{Dictionary, SdoDirection, Value, format_value};
use serde::Serialize;

/// One decoded field of a vendor SDO frame.
#[derive(Clone, Debug, PartialEq)]
pub struct VendorField {
    /// The field's name in the profile, e.g. `A`.
    pub name: String,
    /// The raw little-endian value.
    pub raw: i64,
    /// The object the value belongs to, when the profile says so.
    pub object: Option<(u16, u8)>,
    /// The value as shown: through the object's type, unit and texts when there is one.
    pub text: String,
    /// The object's label name (with its vendor alias), when known.
    pub object_name: Option<String>,
}

/// A frame of a vendor SDO command.
#[derive(Clone, Debug, PartialEq)]
pub struct VendorSdo {
    /// Byte 0 of the frame.
    pub command: u8,
    /// The command's name in the profile, e.g. `Read axis A and B`.
    pub name: String,
    /// The fields, in profile order (fields beyond the data are left out).
    pub fields: Vec<VendorField>,
}

/// Decodes an SDO payload through the node's vendor commands; `None` when the
/// dictionary has no vendor command for byte 0 in this direction.
pub fn decode(dict: &Dictionary, client_to_server: bool, payload: &[u8]) -> Option<VendorSdo> {
    let direction = if client_to_server {
        SdoDirection::Request
    } else {
        SdoDirection::Response
    };
    let command = dict.sdo_command(*payload.first()?, direction)?;
    let fields = command
        .decode(payload)
        .into_iter()
        .zip(&command.fields)
        .map(|(d, spec)| {
            let (text, object_name) = match d.object {
                Some((index, sub)) => {
                    let value = if spec.signed {
                        Value::Signed(d.raw)
                    } else {
                        Value::Unsigned(d.raw as u64)
                    };
                    (
                        format_value(dict.object(index, sub), &value),
                        dict.label_name(index, sub),
                    )
                }
                None => (spec.format(d.raw), None),
            };
            VendorField {
                name: d.name,
                raw: d.raw,
                object: d.object,
                text,
                object_name,
            }
        })
        .collect();
    Some(VendorSdo {
        command: command.command,
        name: command.name.clone(),
        fields,
    })
}

impl VendorSdo {
    /// One-line label, e.g.
    /// `Write axis A and B: A 0x2318:00 A speed command (F0.3.018) = 54 rpm; B 0x3318:00 ... = -54 rpm`.
    pub fn label(&self) -> String {
        let parts: Vec<String> = self
            .fields
            .iter()
            .filter(|f| f.object.is_some() || !self.fields.iter().any(|g| g.object.is_some()))
            .map(|f| match (f.object, &f.object_name) {
                (Some((i, s)), Some(n)) => format!("{} 0x{i:04X}:{s:02X} {n} = {}", f.name, f.text),
                (Some((i, s)), None) => format!("{} 0x{i:04X}:{s:02X} = {}", f.name, f.text),
                (None, _) => format!("{}={}", f.name, f.text),
            })
            .collect();
        format!("{}: {}", self.name, parts.join("; "))
    }

    /// The JSON object of the `vendor_sdo` key.
    pub fn to_json(&self) -> VendorSdoJson<'_> {
        VendorSdoJson {
            command: self.command,
            fields: self
                .fields
                .iter()
                .map(|f| VendorFieldJson {
                    index: f.object.map(|o| o.0),
                    name: &f.name,
                    object_name: f.object_name.as_deref(),
                    raw: f.raw,
                    sub: f.object.map(|o| o.1),
                    text: &f.text,
                })
                .collect(),
            name: &self.name,
        }
    }
}

/// The `vendor_sdo` object of a JSONL frame record (fields in key order).
#[derive(Clone, Debug, Serialize)]
pub struct VendorSdoJson<'a> {
    pub command: u8,
    pub fields: Vec<VendorFieldJson<'a>>,
    pub name: &'a str,
}

/// One field of [`VendorSdoJson`] (fields in key order); `index`, `sub` and
/// `object_name` are `null` when the field belongs to no object.
#[derive(Clone, Debug, Serialize)]
pub struct VendorFieldJson<'a> {
    pub index: Option<u16>,
    pub name: &'a str,
    pub object_name: Option<&'a str>,
    pub raw: i64,
    pub sub: Option<u8>,
    pub text: &'a str,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::od::{ByteField, Expr, ObjectInfo, Profile, SdoCommand};
    use std::sync::Arc;

    fn field(name: &str, offset: u8, length: u8, object: Option<&str>) -> ByteField {
        ByteField {
            name: name.into(),
            offset,
            length,
            signed: object.is_some(),
            object: object.map(|e| Expr::parse(e).unwrap()),
            object_sub: object.map(|_| Expr::parse("sub").unwrap()),
            ..Default::default()
        }
    }

    fn dict() -> Dictionary {
        let mut p = Profile::default();
        for (index, name, alias) in [
            (0x2318, "A speed command", "F0.3.018"),
            (0x3318, "B speed command", "F1.3.018"),
        ] {
            let info = ObjectInfo {
                name: name.into(),
                unit: Some("rpm".into()),
                alias: Some(alias.into()),
                ..Default::default()
            };
            p.objects.insert((index, 0), info);
        }
        p.sdo_commands.push(SdoCommand {
            command: 0xE9,
            direction: SdoDirection::Request,
            name: "Write axis A and B".into(),
            fields: vec![
                field("index", 1, 2, None),
                field("sub", 3, 1, None),
                field("A", 4, 2, Some("index")),
                field("B", 6, 2, Some("index + 0x1000")),
            ],
        });
        Dictionary::new(vec![Arc::new(p)])
    }

    #[test]
    fn dual_axis_write_is_labelled_per_axis_with_units() {
        let v = decode(&dict(), true, &[0xE9, 0x18, 0x23, 0x00, 0x36, 0x00, 0xCA, 0xFF]).unwrap();
        assert_eq!(
            v.label(),
            "Write axis A and B: A 0x2318:00 A speed command (F0.3.018) = 54 rpm; \
             B 0x3318:00 B speed command (F1.3.018) = -54 rpm"
        );
        assert_eq!(serde_json::to_value(v.to_json()).unwrap()["fields"][3]["index"], 0x3318);
    }

    #[test]
    fn other_commands_and_directions_are_not_vendor_frames() {
        assert!(decode(&dict(), false, &[0xE9, 0x18, 0x23, 0, 0, 0, 0, 0]).is_none());
        assert!(decode(&dict(), true, &[0x40, 0x18, 0x23, 0, 0, 0, 0, 0]).is_none());
        assert!(decode(&dict(), true, &[]).is_none());
    }
}
