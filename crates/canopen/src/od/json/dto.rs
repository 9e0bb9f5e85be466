//! The JSON shape of a profile file, as serde reads it. Fields that accept
//! several spellings (numbers as numbers or strings, expressions) stay JSON
//! values here and are checked while converting to a `Profile`.

use std::collections::BTreeMap;

use serde::Deserialize;
use serde_json::Value as Json;

#[derive(Deserialize)]
pub(super) struct ProfileDto {
    #[serde(default)]
    pub(super) format: Option<u64>,
    pub(super) name: String,
    #[serde(default)]
    pub(super) description: Option<String>,
    #[serde(default)]
    pub(super) extends: Vec<String>,
    #[serde(default)]
    pub(super) identification: Vec<IdDto>,
    #[serde(default)]
    pub(super) objects: BTreeMap<String, EntryDto>,
    #[serde(default)]
    pub(super) aliases: BTreeMap<String, String>,
    #[serde(default)]
    pub(super) alias_rules: Vec<AliasRuleDto>,
    #[serde(default)]
    pub(super) emcy: Option<EmcyDto>,
    #[serde(default)]
    pub(super) rpdo: BTreeMap<String, PdoDto>,
    #[serde(default)]
    pub(super) tpdo: BTreeMap<String, PdoDto>,
    #[serde(default)]
    pub(super) pdo_sets: Vec<PdoSetDto>,
    #[serde(default)]
    pub(super) sdo_commands: Vec<SdoCommandDto>,
    #[serde(default)]
    pub(super) procedures: BTreeMap<String, ProcedureDto>,
    #[serde(default)]
    pub(super) axes: Vec<AxisDto>,
}

#[derive(Deserialize)]
pub(super) struct EntryDto {
    #[serde(default)]
    pub(super) name: Option<String>,
    #[serde(default, rename = "type")]
    pub(super) data_type: Option<String>,
    #[serde(default)]
    pub(super) access: Option<String>,
    #[serde(default)]
    pub(super) pdo: Option<String>,
    #[serde(default)]
    pub(super) unit: Option<String>,
    #[serde(default)]
    pub(super) scale: Option<Json>,
    #[serde(default)]
    pub(super) values: BTreeMap<String, String>,
    #[serde(default)]
    pub(super) bits: BTreeMap<String, String>,
    #[serde(default)]
    pub(super) default: Option<Json>,
    #[serde(default)]
    pub(super) min: Option<Json>,
    #[serde(default)]
    pub(super) max: Option<Json>,
    #[serde(default)]
    pub(super) alias: Option<String>,
    #[serde(default)]
    pub(super) description: Option<String>,
    #[serde(default)]
    pub(super) subs: Option<BTreeMap<String, EntryDto>>,
    #[serde(default)]
    pub(super) fields: Vec<FieldDto>,
    #[serde(default)]
    pub(super) meaning: Option<String>,
}

#[derive(Deserialize)]
pub(super) struct IdDto {
    pub(super) object: String,
    #[serde(default)]
    pub(super) value: Option<Json>,
    #[serde(default)]
    pub(super) mask: Option<Json>,
    #[serde(default)]
    pub(super) text: Option<String>,
    #[serde(default, rename = "match")]
    pub(super) mode: Option<String>,
}

#[derive(Deserialize)]
pub(super) struct AliasRuleDto {
    pub(super) pattern: String,
    pub(super) index: Json,
    #[serde(default)]
    pub(super) sub: Option<Json>,
    #[serde(default)]
    pub(super) description: Option<String>,
}

#[derive(Deserialize)]
pub(super) struct EmcyDto {
    #[serde(default)]
    pub(super) codes: BTreeMap<String, String>,
    #[serde(default)]
    pub(super) manufacturer_fields: Vec<FieldDto>,
    /// "Check first" steps per EMCY code (the manual's causes and remedies).
    #[serde(default)]
    pub(super) check: BTreeMap<String, Vec<String>>,
}

#[derive(Deserialize)]
pub(super) struct FieldDto {
    pub(super) name: String,
    pub(super) offset: Json,
    #[serde(default)]
    pub(super) length: Option<Json>,
    #[serde(default)]
    pub(super) signed: bool,
    #[serde(default)]
    pub(super) format: Option<String>,
    #[serde(default)]
    pub(super) values: BTreeMap<String, String>,
    #[serde(default)]
    pub(super) unit: Option<String>,
    #[serde(default)]
    pub(super) scale: Option<Json>,
    #[serde(default)]
    pub(super) object: Option<Json>,
    #[serde(default)]
    pub(super) object_sub: Option<Json>,
}

#[derive(Deserialize)]
pub(super) struct PdoDto {
    #[serde(default)]
    pub(super) cob_id: Option<Json>,
    #[serde(default)]
    pub(super) transmission_type: Option<Json>,
    #[serde(default)]
    pub(super) entries: Vec<Json>,
}

#[derive(Deserialize)]
pub(super) struct PdoSetDto {
    pub(super) name: String,
    #[serde(default)]
    pub(super) description: Option<String>,
    #[serde(default)]
    pub(super) default: bool,
    #[serde(default)]
    pub(super) selected_by: Option<SelectorDto>,
    #[serde(default)]
    pub(super) rpdo: BTreeMap<String, PdoDto>,
    #[serde(default)]
    pub(super) tpdo: BTreeMap<String, PdoDto>,
}

#[derive(Deserialize)]
pub(super) struct SelectorDto {
    pub(super) object: String,
    pub(super) value: Json,
}

#[derive(Deserialize)]
pub(super) struct SdoCommandDto {
    pub(super) command: Json,
    pub(super) direction: String,
    pub(super) name: String,
    #[serde(default)]
    pub(super) fields: Vec<FieldDto>,
}

#[derive(Deserialize)]
pub(super) struct ProcedureDto {
    #[serde(default)]
    pub(super) description: Option<String>,
    #[serde(default)]
    pub(super) params: Vec<ParamDto>,
    #[serde(default)]
    pub(super) steps: Vec<Json>,
}

#[derive(Deserialize)]
pub(super) struct ParamDto {
    pub(super) name: String,
    #[serde(default)]
    pub(super) unit: Option<String>,
    #[serde(default)]
    pub(super) description: Option<String>,
    #[serde(default)]
    pub(super) default: Option<Json>,
}

#[derive(Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum StepDto {
    SdoWrite {
        object: String,
        value: Json,
        #[serde(default, rename = "type")]
        data_type: Option<String>,
    },
    SdoRead {
        object: String,
    },
    Nmt(NmtDto),
    Wait {
        #[serde(default)]
        object: Option<String>,
        #[serde(default)]
        mask: Option<Json>,
        equals: Json,
        #[serde(default)]
        timeout_ms: Option<Json>,
        #[serde(default)]
        fail_if: Option<FailDto>,
    },
    Frame {
        id: Json,
        data: String,
    },
    DelayMs(Json),
}

/// A `wait` step's failure condition: `(value & mask) == equals` means `text`.
#[derive(Deserialize)]
pub(super) struct FailDto {
    #[serde(default)]
    pub(super) mask: Option<Json>,
    pub(super) equals: Json,
    pub(super) text: String,
}

#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum NmtDto {
    Name(String),
    Full {
        command: String,
        #[serde(default)]
        node: Option<Json>,
    },
}

#[derive(Deserialize)]
pub(super) struct AxisDto {
    pub(super) name: String,
    #[serde(default)]
    pub(super) description: Option<String>,
    #[serde(default)]
    pub(super) objects: Vec<String>,
    #[serde(default)]
    pub(super) emcy_field: Option<String>,
}
