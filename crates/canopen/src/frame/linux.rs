//! The flags of a Linux SocketCAN identifier and of a CAN FD frame (`<linux/can.h>`), as
//! the socket, candump logs and pcapng's `LINKTYPE_CAN_SOCKETCAN` carry them.

/// `CAN_EFF_FLAG`: a 29-bit identifier.
pub const CAN_EFF_FLAG: u32 = 0x8000_0000;
/// `CAN_RTR_FLAG`: a remote transmission request.
pub const CAN_RTR_FLAG: u32 = 0x4000_0000;
/// `CAN_ERR_FLAG`: an error frame (the identifier holds the error class).
pub const CAN_ERR_FLAG: u32 = 0x2000_0000;
/// `CAN_EFF_MASK`: the bits of a 29-bit identifier (and of an error class).
pub const CAN_EFF_MASK: u32 = 0x1FFF_FFFF;
/// `CANFD_BRS`: bit rate switch.
pub const CANFD_BRS: u8 = 0x01;
/// `CANFD_ESI`: error state indicator.
pub const CANFD_ESI: u8 = 0x02;
/// `CANFD_FDF`: a CAN FD frame.
pub const CANFD_FDF: u8 = 0x04;
