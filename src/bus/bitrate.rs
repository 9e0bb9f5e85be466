//! The bit rate a SocketCAN interface is configured with, read over netlink (what `ip -d
//! link show can0` prints as `bitrate`), for the bus load of a live session. IO only: the
//! choice between it, `--bitrate` and the assumed rate is
//! [`crate::output::busload::Bitrate::of_live`].

use socketcan::nl::CanInterface;

/// The nominal bit rate of SocketCAN interface `iface` in bit/s, or why there is none, in
/// words that follow the interface's name (`reports no bit rate`: a vcan, a CAN interface
/// not configured yet, or not a CAN interface).
pub fn configured(iface: &str) -> Result<u64, String> {
    let link = CanInterface::open(iface).map_err(|e| format!("cannot be asked for its bit rate ({e})"))?;
    match link.bit_rate() {
        Ok(Some(bps)) if bps > 0 => Ok(u64::from(bps)),
        Ok(_) => Err("reports no bit rate".to_string()),
        Err(e) => Err(format!("cannot be asked for its bit rate ({e})")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_interface_that_is_not_can_reports_no_bit_rate() {
        assert_eq!(configured("lo"), Err("reports no bit rate".to_string()));
    }

    #[test]
    fn a_missing_interface_says_it_cannot_be_asked() {
        let why = configured("nosuchcan7").unwrap_err();
        assert!(why.starts_with("cannot be asked for its bit rate ("), "{why}");
    }
}
