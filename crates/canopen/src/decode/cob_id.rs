//! COB-ID classification: the CiA 301 predefined connection set, plus COB-IDs
//! moved by a profile, an EDS/DCF or a sniffed SDO write.

use super::kind::Kind;
use std::collections::HashMap;

/// What a COB-ID is used for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Route {
    pub kind: Kind,
    /// The node the frame belongs to (producer of TPDO/EMCY/heartbeat/SDO server, consumer of RPDO).
    pub node: Option<u8>,
    /// PDO number 1..=4 (or higher when moved), 0 otherwise.
    pub pdo: u16,
    /// Set when the COB-ID is reserved or outside the predefined set rules (e.g. node 0).
    pub reserved: bool,
}

impl Route {
    const fn new(kind: Kind, node: Option<u8>, pdo: u16) -> Route {
        Route {
            kind,
            node,
            pdo,
            reserved: false,
        }
    }
}

/// COB-ID key: 11- or 29-bit id plus the extended flag.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct CobId {
    pub id: u32,
    pub ext: bool,
}

/// The classification table: predefined set plus overrides.
#[derive(Clone, Debug, Default)]
pub(crate) struct CobTable {
    moved: HashMap<CobId, Route>,
}

impl CobTable {
    /// Routes `cob` to `route`, e.g. after a write of 0x1800:1 = 0x00000290. The
    /// previous COB-ID of the same object (if it was predefined) is left alone:
    /// CiA 301 allows both to coexist until the old one is reused.
    pub fn assign(&mut self, cob: CobId, route: Route) {
        self.moved
            .retain(|_, r| !(r.kind == route.kind && r.node == route.node && r.pdo == route.pdo));
        self.moved.insert(cob, route);
    }

    /// Forgets an assignment (e.g. the PDO was made invalid with bit 31).
    pub fn unassign(&mut self, kind: Kind, node: Option<u8>, pdo: u16) {
        self.moved
            .retain(|_, r| !(r.kind == kind && r.node == node && r.pdo == pdo));
    }

    /// How a frame with this id is to be read.
    pub fn route(&self, id: u32, ext: bool) -> Route {
        // Most buses move no COB-ID: skip hashing the id then.
        if !self.moved.is_empty()
            && let Some(r) = self.moved.get(&CobId { id, ext })
        {
            return *r;
        }
        if ext {
            return Route::new(Kind::Other, None, 0);
        }
        predefined(id)
    }
}

/// CiA 301 predefined connection set for an 11-bit id (a larger id is [`Kind::Other`]).
#[inline]
pub fn predefined(id: u32) -> Route {
    match PREDEFINED.get(id as usize) {
        Some(route) => *route,
        None => Route::new(Kind::Other, None, 0),
    }
}

/// [`predefined`] of every 11-bit id, made at compile time: a frame is routed by one load.
static PREDEFINED: [Route; 2048] = {
    let mut table = [Route::new(Kind::Other, None, 0); 2048];
    let mut id = 0;
    while id < 2048 {
        table[id] = predefined_route(id as u32);
        id += 1;
    }
    table
};

/// The route of a predefined connection with a node-ID in its low 7 bits (node 0 is
/// reserved).
const fn with_node(id: u32, kind: Kind, pdo: u16) -> Route {
    match (id & 0x7F) as u8 {
        0 => Route {
            kind: Kind::Other,
            node: None,
            pdo: 0,
            reserved: true,
        },
        node => Route::new(kind, Some(node), pdo),
    }
}

/// The predefined connection set's route for an 11-bit id (CiA 301 7.3.5).
const fn predefined_route(id: u32) -> Route {
    match id {
        0x000 => Route::new(Kind::Nmt, None, 0),
        0x080 => Route::new(Kind::Sync, None, 0),
        0x100 => Route::new(Kind::Time, None, 0),
        0x7E4 | 0x7E5 => Route::new(Kind::Lss, None, 0),
        _ => match id >> 7 {
            0x1 => with_node(id, Kind::Emcy, 0),
            0x3 => with_node(id, Kind::Tpdo, 1),
            0x4 => with_node(id, Kind::Rpdo, 1),
            0x5 => with_node(id, Kind::Tpdo, 2),
            0x6 => with_node(id, Kind::Rpdo, 2),
            0x7 => with_node(id, Kind::Tpdo, 3),
            0x8 => with_node(id, Kind::Rpdo, 3),
            0x9 => with_node(id, Kind::Tpdo, 4),
            0xA => with_node(id, Kind::Rpdo, 4),
            0xB => with_node(id, Kind::SdoTx, 0),
            0xC => with_node(id, Kind::SdoRx, 0),
            0xE => with_node(id, Kind::Heartbeat, 0),
            // 0x001-0x07F, 0x101-0x17F, 0x680-0x6FF and 0x780-0x7FF (except LSS) are
            // reserved or used by other CiA specifications.
            _ => Route {
                kind: Kind::Other,
                node: None,
                pdo: 0,
                reserved: is_reserved(id),
            },
        },
    }
}

/// CiA 301 reserved COB-IDs (CiA 301 7.3.5, table 65 and CiA 305 for LSS).
pub(crate) const fn is_reserved(id: u32) -> bool {
    matches!(id, 0x001..=0x07F | 0x101..=0x180 | 0x580 | 0x600 | 0x6E0..=0x6FF | 0x700 | 0x780..=0x7FF)
        && !matches!(id, 0x7E4 | 0x7E5)
}

/// What an 11-bit COB-ID is reserved for, when a PDO or a SYNC producer is to be given it:
/// a service of the predefined connection set whose id is fixed, or that every node uses
/// (NMT, SYNC, EMCY, TIME, SDO, heartbeat, LSS), or an id CiA 301 restricts (7.3.5,
/// "restricted CAN-IDs"). `None` for a free id (a PDO's own range, or 29-bit ids, which
/// the predefined set does not use). The text names the owner: `node 2's SDO request`.
pub fn reserved_for(id: u32) -> Option<String> {
    let node = id & 0x7F;
    Some(match id {
        0x000 => "NMT (node control)".into(),
        0x080 => "SYNC".into(),
        0x081..=0x0FF => format!("node {node}'s EMCY"),
        0x100 => "TIME".into(),
        0x581..=0x5FF => format!("node {node}'s SDO response"),
        0x601..=0x67F => format!("node {node}'s SDO request"),
        0x701..=0x77F => format!("node {node}'s heartbeat (NMT error control)"),
        0x7E4 => "LSS (slave to master)".into(),
        0x7E5 => "LSS (master to slave)".into(),
        _ if id <= 0x7FF && is_reserved(id) => "restricted by CiA 301".into(),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reserved_ids_name_their_owner() {
        assert_eq!(reserved_for(0x602).as_deref(), Some("node 2's SDO request"));
        assert_eq!(reserved_for(0x5FF).as_deref(), Some("node 127's SDO response"));
        assert_eq!(reserved_for(0x080).as_deref(), Some("SYNC"));
        assert_eq!(reserved_for(0x085).as_deref(), Some("node 5's EMCY"));
        assert_eq!(reserved_for(0x000).as_deref(), Some("NMT (node control)"));
        assert_eq!(reserved_for(0x100).as_deref(), Some("TIME"));
        assert_eq!(
            reserved_for(0x77F).as_deref(),
            Some("node 127's heartbeat (NMT error control)")
        );
        assert!(reserved_for(0x7E4).unwrap().starts_with("LSS"));
        assert!(reserved_for(0x7E5).unwrap().starts_with("LSS"));
        assert_eq!(reserved_for(0x050).as_deref(), Some("restricted by CiA 301"));
        assert_eq!(reserved_for(0x6E0).as_deref(), Some("restricted by CiA 301"));
        for free in [0x181, 0x1FF, 0x202, 0x57F, 0x680, 0x6DF, 0x12345, 0x602 | 0x1000] {
            assert_eq!(reserved_for(free), None, "{free:#x}");
        }
    }

    #[test]
    fn predefined_set() {
        assert_eq!(predefined(0x000).kind, Kind::Nmt);
        assert_eq!(predefined(0x080).kind, Kind::Sync);
        let e = predefined(0x085);
        assert_eq!((e.kind, e.node), (Kind::Emcy, Some(5)));
        assert_eq!(predefined(0x100).kind, Kind::Time);
        assert_eq!(predefined(0x182), Route::new(Kind::Tpdo, Some(2), 1));
        assert_eq!(predefined(0x202), Route::new(Kind::Rpdo, Some(2), 1));
        assert_eq!(predefined(0x4FF), Route::new(Kind::Tpdo, Some(127), 4));
        assert_eq!(predefined(0x501), Route::new(Kind::Rpdo, Some(1), 4));
        assert_eq!(predefined(0x581), Route::new(Kind::SdoTx, Some(1), 0));
        assert_eq!(predefined(0x67F), Route::new(Kind::SdoRx, Some(127), 0));
        assert_eq!(predefined(0x705), Route::new(Kind::Heartbeat, Some(5), 0));
        assert_eq!(predefined(0x7E5).kind, Kind::Lss);
        assert_eq!(predefined(0x7E4).kind, Kind::Lss);
    }

    #[test]
    fn node_zero_and_gaps_are_reserved_other() {
        for id in [0x180, 0x580, 0x600, 0x700, 0x050, 0x7F0] {
            let r = predefined(id);
            assert_eq!(r.kind, Kind::Other, "{id:#x}");
            assert!(r.reserved, "{id:#x}");
        }
        let r = predefined(0x6A0);
        assert_eq!(r.kind, Kind::Other);
        assert!(!r.reserved);
    }

    #[test]
    fn moved_cob_ids_win() {
        let mut t = CobTable::default();
        t.assign(CobId { id: 0x290, ext: false }, Route::new(Kind::Tpdo, Some(16), 1));
        assert_eq!(t.route(0x290, false), Route::new(Kind::Tpdo, Some(16), 1));
        t.assign(
            CobId {
                id: 0x18FF0010,
                ext: true,
            },
            Route::new(Kind::Tpdo, Some(16), 1),
        );
        assert_eq!(
            t.route(0x290, false).node,
            Some(0x10),
            "0x290 is predefined TPDO2 of node 0x10 again"
        );
        assert_eq!(t.route(0x290, false).pdo, 2);
        assert_eq!(t.route(0x18FF0010, true).pdo, 1);
        t.unassign(Kind::Tpdo, Some(16), 1);
        assert_eq!(t.route(0x18FF0010, true).kind, Kind::Other);
    }
}
