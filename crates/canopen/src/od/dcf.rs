//! Writes an object dictionary as a CiA 306 EDS, or as a DCF when values are given (the
//! `ParameterValue` of each object and `[DeviceComissioning]` with the node-ID), so other
//! tools (the python `canopen` library, CANopen Magic, PLC configurators) can load it.
//! Pure: entries in, text out.

use super::object::Access;
use super::value::DataType;
use std::fmt::Write;

/// One (index, sub) to write.
#[derive(Clone, Debug, PartialEq)]
pub struct DcfEntry {
    pub index: u16,
    pub sub: u8,
    pub name: String,
    pub data_type: DataType,
    pub access: Access,
    /// `DefaultValue`, little-endian bytes (none for domains).
    pub default: Option<Vec<u8>>,
    /// `ParameterValue` (DCF): the value the node has, little-endian bytes.
    pub value: Option<Vec<u8>>,
}

/// What `[DeviceInfo]` and `[DeviceComissioning]` say.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DeviceInfo {
    pub vendor_name: String,
    pub vendor_number: u32,
    pub product_name: String,
    pub product_number: u32,
    pub revision_number: u32,
    /// Set for a DCF: the node the values were read from.
    pub node_id: Option<u8>,
    /// `[FileInfo] Description`.
    pub description: String,
    /// `[FileInfo] FileName`: the name of the file written (empty when there is none).
    pub file_name: String,
}

fn access_text(a: Access) -> &'static str {
    match a {
        Access::Rw => "rw",
        Access::Ro => "ro",
        Access::Wo => "wo",
        Access::Const => "const",
        Access::Rww => "rww",
        Access::Rwr => "rwr",
    }
}

/// A value as an EDS/DCF value text: integers in hex (`0x...`) or decimal for signed
/// types, floats in decimal, visible strings as written, octet strings as hex digits.
pub fn value_text(data_type: DataType, bytes: &[u8]) -> Option<String> {
    use DataType::*;
    let mut le = [0u8; 8];
    let n = bytes.len().min(8);
    le[..n].copy_from_slice(&bytes[..n]);
    let unsigned = u64::from_le_bytes(le);
    Some(match data_type {
        Boolean => (unsigned & 1).to_string(),
        U8 | U16 | U24 | U32 | U40 | U48 | U56 | U64 => format!("0x{unsigned:X}"),
        I8 | I16 | I24 | I32 | I40 | I48 | I56 | I64 => {
            let bits = data_type.size().unwrap_or(8) * 8;
            let shift = 64 - bits as u32;
            (((unsigned << shift) as i64) >> shift).to_string()
        }
        F32 => f32::from_le_bytes([le[0], le[1], le[2], le[3]]).to_string(),
        F64 => f64::from_le_bytes(le).to_string(),
        VisibleString => String::from_utf8_lossy(bytes).trim_end_matches('\0').to_string(),
        OctetString => bytes.iter().fold(String::new(), |mut s, b| {
            let _ = write!(s, "{b:02X}");
            s
        }),
        UnicodeString | TimeOfDay | TimeDifference | Domain => return None,
    })
}

fn write_var(out: &mut String, e: &DcfEntry, dcf: bool) {
    let _ = writeln!(out, "ParameterName={}", e.name);
    let _ = writeln!(out, "ObjectType=0x7");
    let _ = writeln!(out, "DataType=0x{:04X}", e.data_type.code());
    let _ = writeln!(out, "AccessType={}", access_text(e.access));
    if let Some(d) = e.default.as_deref().and_then(|d| value_text(e.data_type, d)) {
        let _ = writeln!(out, "DefaultValue={d}");
    }
    let mappable = matches!(e.access, Access::Rww | Access::Rwr);
    let _ = writeln!(out, "PDOMapping={}", u8::from(mappable));
    if dcf && let Some(v) = e.value.as_deref().and_then(|v| value_text(e.data_type, v)) {
        let _ = writeln!(out, "ParameterValue={v}");
    }
    out.push('\n');
}

/// Which indexes belong in an object list section.
type IndexGroup = fn(u16) -> bool;

/// The EDS (no values) or DCF (values and node-ID) text of `entries`.
pub fn write(info: &DeviceInfo, entries: &[DcfEntry]) -> String {
    let dcf = info.node_id.is_some();
    let mut entries: Vec<&DcfEntry> = entries.iter().collect();
    entries.sort_by_key(|e| (e.index, e.sub));
    let mut indexes: Vec<u16> = entries.iter().map(|e| e.index).collect();
    indexes.dedup();
    let mut out = String::new();
    let _ = writeln!(out, "[FileInfo]");
    let _ = writeln!(out, "FileName={}", info.file_name);
    let _ = writeln!(out, "FileVersion=1");
    let _ = writeln!(out, "FileRevision=0");
    let _ = writeln!(out, "EDSVersion=4.0");
    let _ = writeln!(out, "Description={}", info.description);
    let _ = writeln!(out, "CreatedBy=cotui\n");
    let _ = writeln!(out, "[DeviceInfo]");
    let _ = writeln!(out, "VendorName={}", info.vendor_name);
    let _ = writeln!(out, "VendorNumber=0x{:08X}", info.vendor_number);
    let _ = writeln!(out, "ProductName={}", info.product_name);
    let _ = writeln!(out, "ProductNumber=0x{:08X}", info.product_number);
    let _ = writeln!(out, "RevisionNumber=0x{:08X}", info.revision_number);
    for rate in [10, 20, 50, 125, 250, 500, 800, 1000] {
        let _ = writeln!(out, "BaudRate_{rate}=1");
    }
    let _ = writeln!(
        out,
        "SimpleBootUpMaster=0\nSimpleBootUpSlave=1\nGranularity=8\nDynamicChannelsSupported=0"
    );
    let _ = writeln!(out, "GroupMessaging=0\nNrOfRXPDO=4\nNrOfTXPDO=4\nLSS_Supported=1\n");
    if let Some(node) = info.node_id {
        let _ = writeln!(out, "[DeviceComissioning]\nNodeID={node}\nBaudrate=500\n");
    }
    let _ = writeln!(out, "[DummyUsage]");
    for t in 1..=7 {
        let _ = writeln!(out, "Dummy000{t}=0");
    }
    out.push('\n');
    let groups: [(&str, IndexGroup); 3] = [
        ("MandatoryObjects", |i| matches!(i, 0x1000 | 0x1001 | 0x1018)),
        ("OptionalObjects", |i| {
            ((0x1000..=0x1FFF).contains(&i) && !matches!(i, 0x1000 | 0x1001 | 0x1018)) || i >= 0x6000
        }),
        ("ManufacturerObjects", |i| (0x2000..=0x5FFF).contains(&i)),
    ];
    for (section, member) in groups {
        let list: Vec<u16> = indexes.iter().copied().filter(|i| member(*i)).collect();
        let _ = writeln!(out, "[{section}]\nSupportedObjects={}", list.len());
        for (n, i) in list.iter().enumerate() {
            let _ = writeln!(out, "{}=0x{i:04X}", n + 1);
        }
        out.push('\n');
        for index in list {
            let subs: Vec<&&DcfEntry> = entries.iter().filter(|e| e.index == index).collect();
            let _ = writeln!(out, "[{index:04X}]");
            match subs.as_slice() {
                [only] if only.sub == 0 => write_var(&mut out, only, dcf),
                _ => {
                    let name = subs.iter().find(|e| e.sub == 0).map_or("", |e| e.name.as_str());
                    let _ = writeln!(out, "ParameterName={}", if name.is_empty() { "Record" } else { name });
                    let _ = writeln!(out, "ObjectType=0x9");
                    let _ = writeln!(out, "SubNumber={}\n", subs.len());
                    for e in subs {
                        let _ = writeln!(out, "[{index:04X}sub{:X}]", e.sub);
                        write_var(&mut out, e, dcf);
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(index: u16, sub: u8, name: &str, t: DataType, access: Access, v: &[u8]) -> DcfEntry {
        DcfEntry {
            index,
            sub,
            name: name.into(),
            data_type: t,
            access,
            default: Some(v.to_vec()),
            value: Some(v.to_vec()),
        }
    }

    #[test]
    fn values_are_written_as_eds_value_texts() {
        assert_eq!(value_text(DataType::U32, &[0x92, 0x01, 0x02, 0x00]).unwrap(), "0x20192");
        assert_eq!(value_text(DataType::I16, &[0xFE, 0xFF]).unwrap(), "-2");
        assert_eq!(value_text(DataType::I32, &[0x10, 0x27, 0, 0]).unwrap(), "10000");
        assert_eq!(value_text(DataType::VisibleString, b"AB\0").unwrap(), "AB");
        assert_eq!(value_text(DataType::OctetString, &[1, 0xAB]).unwrap(), "01AB");
        assert_eq!(value_text(DataType::Domain, &[1]), None);
    }

    #[test]
    fn a_dcf_has_records_values_and_the_node_id() {
        let entries = [
            entry(0x1018, 0, "Identity", DataType::U8, Access::Const, &[2]),
            entry(0x1018, 1, "Vendor-ID", DataType::U32, Access::Ro, &[0x2C, 0x01, 0, 0]),
            entry(0x1018, 2, "Product code", DataType::U32, Access::Ro, &[2, 0, 0, 0]),
            entry(
                0x1000,
                0,
                "Device type",
                DataType::U32,
                Access::Ro,
                &[0x92, 0x01, 0x02, 0],
            ),
            entry(0x2000, 0, "Vendor gain", DataType::I16, Access::Rw, &[0xFF, 0xFF]),
            entry(0x6040, 0, "Controlword", DataType::U16, Access::Rww, &[6, 0]),
        ];
        let info = DeviceInfo {
            node_id: Some(5),
            file_name: "node5.dcf".into(),
            ..DeviceInfo::default()
        };
        let text = write(&info, &entries);
        assert!(text.starts_with("[FileInfo]\nFileName=node5.dcf\n"), "{text}");
        assert!(text.contains("[DeviceComissioning]\nNodeID=5\n"));
        assert!(text.contains("[MandatoryObjects]\nSupportedObjects=2\n1=0x1000\n2=0x1018\n"));
        assert!(text.contains("[1018]\nParameterName=Identity\nObjectType=0x9\nSubNumber=3\n"));
        assert!(text.contains("[1018sub1]\nParameterName=Vendor-ID\nObjectType=0x7\nDataType=0x0007\nAccessType=ro\nDefaultValue=0x12C\nPDOMapping=0\nParameterValue=0x12C\n"));
        assert!(text.contains(
            "[2000]\nParameterName=Vendor gain\nObjectType=0x7\nDataType=0x0003\nAccessType=rw\nDefaultValue=-1\n"
        ));
        assert!(text.contains("[6040]\nParameterName=Controlword\nObjectType=0x7\nDataType=0x0006\nAccessType=rww\nDefaultValue=0x6\nPDOMapping=1\n"));
        // Our own importer reads it back.
        let (profile, warnings) = crate::od::eds::import("test.dcf", &text, 5);
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(profile.object(0x2000, 0).map(|o| o.name.as_str()), Some("Vendor gain"));
        assert_eq!(profile.object(0x6040, 0).map(|o| o.access), Some(Access::Rww));
    }
}
