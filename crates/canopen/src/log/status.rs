//! The SocketCAN error frames (linux/can/error.h) that stand for the controller states and
//! bus errors other log formats write as text (ASC status lines, TRC and PEAK CSV status,
//! error and error counter lines), so that they take the path of candump error frames.

use crate::frame::{Flags, Frame};

/// `CAN_ERR_CRTL`: controller problem (state in data byte 1).
const CAN_ERR_CRTL: u32 = 0x004;
/// `CAN_ERR_PROT`: protocol violation.
const CAN_ERR_PROT: u32 = 0x008;
/// `CAN_ERR_BUSOFF`.
const CAN_ERR_BUSOFF: u32 = 0x040;
/// `CAN_ERR_BUSERROR`.
pub(crate) const CAN_ERR_BUSERROR: u32 = 0x080;
/// `CAN_ERR_CNT`: error counters in data bytes 6 (TX) and 7 (RX).
const CAN_ERR_CNT: u32 = 0x200;

/// A controller state a log reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum State {
    Active,
    Warning,
    Passive,
    BusOff,
}

/// The error frame a SocketCAN controller sends on entering `state`: bus off as
/// `CAN_ERR_BUSOFF`, the others as `CAN_ERR_CRTL` with the TX or RX bit of the larger
/// counter, plus `CAN_ERR_CNT` when both counters are known.
pub(crate) fn state_frame(state: State, counters: Option<(u32, u32)>) -> Frame {
    let (tx, rx) = counters.unwrap_or((0, 0));
    let side = |tx_bit: u8, rx_bit: u8| if rx > tx { rx_bit } else { tx_bit };
    let mut f = error_frame(CAN_ERR_CRTL);
    match state {
        State::BusOff => f.id = CAN_ERR_BUSOFF,
        State::Passive => f.data[1] = side(0x20, 0x10),
        State::Warning => f.data[1] = side(0x08, 0x04),
        State::Active => f.data[1] = 0x40,
    }
    if counters.is_some() {
        f.id |= CAN_ERR_CNT;
        f.data[6] = tx.min(255) as u8;
        f.data[7] = rx.min(255) as u8;
    }
    f
}

/// The error frame of an error counter report (TRC `EC` lines): `CAN_ERR_CNT` with both
/// counters and the state they imply, as a SocketCAN controller reports it: error passive
/// from 128, error warning from 96, else error active.
pub(crate) fn counters_frame(tx: u32, rx: u32) -> Frame {
    let state = match tx.max(rx) {
        128.. => State::Passive,
        96.. => State::Warning,
        _ => State::Active,
    };
    state_frame(state, Some((tx, rx)))
}

/// A bus error with no detail (ASC `ErrorFrame`): `CAN_ERR_BUSERROR`, 8 zero bytes.
pub(crate) fn bus_error() -> Frame {
    error_frame(CAN_ERR_BUSERROR)
}

/// A bus error seen as an error frame on the wire (TRC `Error`/`ER` lines): bus error and
/// protocol violation.
pub(crate) fn protocol_error() -> Frame {
    error_frame(CAN_ERR_BUSERROR | CAN_ERR_PROT)
}

fn error_frame(class: u32) -> Frame {
    let mut f = Frame {
        id: class,
        len: 8,
        ..Frame::default()
    };
    f.flags.set(Flags::ERR, true);
    f
}
