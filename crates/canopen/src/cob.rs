//! COB-IDs of the CiA 301 predefined connection set: which identifier each service of a
//! node uses by default. Build identifiers with these, never with `0x600 + node` sums.
//! (Classifying a received identifier, with moved COB-IDs, is `decode::cob_id`.)

/// NMT module control (the master's commands to every node).
pub const NMT: u32 = 0x000;
/// SYNC, by default.
pub const SYNC: u32 = 0x080;
/// TIME stamp, by default.
pub const TIME: u32 = 0x100;
/// LSS, slaves to master.
pub const LSS_SLAVE: u32 = 0x7E4;
/// LSS, master to slaves.
pub const LSS_MASTER: u32 = 0x7E5;

/// `node`'s emergency message (0x080 + node).
pub const fn emcy(node: u8) -> u32 {
    0x080 + node as u32
}

/// `node`'s transmit PDO `num` (1..=4; 0x180, 0x280, 0x380, 0x480 + node).
pub const fn tpdo(num: u8, node: u8) -> u32 {
    0x080 + 0x100 * num as u32 + node as u32
}

/// `node`'s receive PDO `num` (1..=4; 0x200, 0x300, 0x400, 0x500 + node).
pub const fn rpdo(num: u8, node: u8) -> u32 {
    0x100 + 0x100 * num as u32 + node as u32
}

/// SDO server to client: `node`'s answers (0x580 + node).
pub const fn sdo_response(node: u8) -> u32 {
    0x580 + node as u32
}

/// SDO client to server: requests to `node` (0x600 + node).
pub const fn sdo_request(node: u8) -> u32 {
    0x600 + node as u32
}

/// NMT error control: `node`'s heartbeat, boot-up and guarding answers (0x700 + node).
pub const fn heartbeat(node: u8) -> u32 {
    0x700 + node as u32
}

/// The node whose heartbeat (or boot-up) `id` is: 0x701..=0x77F give 1..=127.
pub const fn heartbeat_node(id: u32) -> Option<u8> {
    if id > heartbeat(0) && id <= heartbeat(127) {
        Some((id - heartbeat(0)) as u8)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_predefined_connection_set_of_cia_301() {
        assert_eq!(emcy(1), 0x81);
        assert_eq!(
            [tpdo(1, 5), tpdo(2, 5), tpdo(3, 5), tpdo(4, 5)],
            [0x185, 0x285, 0x385, 0x485]
        );
        assert_eq!(
            [rpdo(1, 5), rpdo(2, 5), rpdo(3, 5), rpdo(4, 5)],
            [0x205, 0x305, 0x405, 0x505]
        );
        assert_eq!((sdo_response(127), sdo_request(127)), (0x5FF, 0x67F));
        assert_eq!(heartbeat(3), 0x703);
        assert_eq!(
            [0x700, 0x701, 0x77F, 0x780].map(heartbeat_node),
            [None, Some(1), Some(127), None]
        );
    }
}
