//! The commander: NMT, SDO, LSS, CiA 402 drive sequences, scan and record, as a library
//! API shared by the command line and the TUI palette.

pub mod complete;
pub mod cyclic;
pub mod dcf;
pub mod drive;
pub mod error;
pub mod exec;
pub mod grammar;
pub mod listen_first;
pub mod lss;
pub mod nmt;
pub mod object;
pub mod pdo;
pub mod record;
pub mod registry;
pub mod report;
pub mod run;
pub mod scan;
pub mod sdo;
pub mod send;
pub mod spec;
pub mod stop;
pub mod sync;
pub mod syntax;
pub mod time_order;
pub mod transmit_line;
pub mod transmit_list;
pub mod transmit_run;
pub mod value;
pub mod watch;
pub mod watch_poll;
pub mod watch_table;
pub mod words;
pub mod write;

pub use drive::DriveAction;
pub use error::{CommandError, ExitCode, ParseError};
pub use exec::{execute, execute_saying, execute_until};
pub use nmt::NmtAction;
pub use object::SdoOptions;
pub use registry::{Command, Commander};
pub use report::Reported;
pub(crate) use report::to_json;
pub use run::command::RunSpec;
pub use spec::{Outcome, Spec, candump};
pub use syntax::parse_command;
