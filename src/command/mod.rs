//! The commander: NMT, SDO, CiA 402 drive sequences, scan and record, as a library
//! API shared by the command line and the TUI palette.

pub mod drive;
pub mod error;
pub mod exec;
pub mod grammar;
pub mod nmt;
pub mod record;
pub mod run;
pub mod scan;
pub mod sdo;
pub mod stop;
pub mod value;

pub use error::CommandError;
pub use exec::{Outcome, execute};
pub use grammar::{Command, DriveAction, NmtAction, RunSpec, SdoOptions, parse_command};
