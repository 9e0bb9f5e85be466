//! TEMPORARY stand-in until the SDO tracker branch lands.
use crate::od::Dictionary;
#[derive(Debug)]
pub struct SdoFrame {
    pub index: Option<u16>,
    pub sub: Option<u8>,
}
impl SdoFrame {
    pub fn label(&self) -> String {
        String::new()
    }
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::Value::Null
    }
    pub fn malformed(&self) -> Option<String> {
        None
    }
}
pub struct Transaction {
    pub node: u8,
    pub index: u16,
    pub sub: u8,
    pub data: Vec<u8>,
    pub end_ns: u64,
}
impl Transaction {
    pub fn is_ok(&self) -> bool {
        true
    }
    pub fn label(&self, _d: &Dictionary) -> String {
        String::new()
    }
    pub fn to_json(&self, _d: &Dictionary) -> serde_json::Value {
        serde_json::Value::Null
    }
}
#[derive(Default)]
pub struct SdoTracker;
impl SdoTracker {
    pub fn new() -> Self {
        SdoTracker
    }
    pub fn on_frame(&mut self, _seq: u64, _ts: u64, _node: u8, _c2s: bool, _p: &[u8], _d: &Dictionary) -> SdoFrame {
        SdoFrame { index: None, sub: None }
    }
    pub fn take_completed(&mut self) -> Vec<Transaction> {
        vec![]
    }
    pub fn finish(&mut self) -> Vec<Transaction> {
        vec![]
    }
}
