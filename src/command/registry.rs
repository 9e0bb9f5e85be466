//! The one list of the commander's commands. Each line names a command's declaration (its
//! words: a clap `Args` after the options in front, [`On`], or a group such as
//! `sdo read|write`) and its parsed form (a [`Spec`]): the `commands!` macro makes of it the
//! clap subcommands ([`Commander`]), the parsed command ([`Command`]) and their dispatch,
//! so that adding a command is its module plus one line here.

use super::cyclic::Source;
use super::error::{CommandError, ParseError};
use super::spec::{Ctx, Declared, Known, Outcome, Preview, Spec};
use super::words::On;
use super::{dcf, drive, lss, nmt, object, pdo, record, run, scan, send, stop, sync, watch};
use crate::od::bind::Bindings;

/// Makes [`Commander`] and [`Command`] of the list of commands: `Variant(Declaration) => Spec;`,
/// each with its help text (doc comment) and clap attributes.
macro_rules! commands {
    ($($(#[$attr:meta])* $variant:ident($declared:ty) => $spec:ty;)*) => {
        /// The commander commands as clap declares them. `B`: the options in front of every
        /// command (see [`super::words::Session`]), `D`: the dictionary options of the
        /// commands that name objects (`sdo`, `run`, `pdo`, `dcf`).
        /// Each command's arguments are declared when it is parsed or its help is shown
        /// (`defer`): a command line pays only for its own command.
        #[derive(clap::Subcommand, Clone, Debug)]
        #[command(defer = true)]
        pub enum Commander<B: clap::Args, D: clap::Args> {
            $($(#[$attr])* $variant($declared),)*
        }

        /// One command of the commander, parsed (the interface is chosen separately).
        #[derive(Clone, Debug, PartialEq)]
        pub enum Command {
            $($variant($spec),)*
        }

        impl<B: clap::Args, D: clap::Args> Commander<B, D> {
            /// The options in front of the command (the command line's bus options).
            pub fn bus(&self) -> &B {
                match self {
                    $(Commander::$variant(c) => Declared::<B, D>::bus(c),)*
                }
            }

            /// The dictionary options, for the commands that take them.
            pub fn dict(&self) -> Option<&D> {
                match self {
                    $(Commander::$variant(c) => Declared::<B, D>::dict(c),)*
                }
            }

            /// What failures are prefixed with: `cotui sdo read: ...`.
            pub fn name(&self) -> &'static str {
                match self {
                    $(Commander::$variant(c) => Declared::<B, D>::name(c),)*
                }
            }

            /// The command the words make, or why they make none.
            pub fn command(&self) -> Result<Command, ParseError> {
                Ok(match self {
                    $(Commander::$variant(c) => Command::$variant(Declared::<B, D>::spec(c)?),)*
                })
            }
        }

        /// Each command as its own [`Spec`] says.
        impl Spec for Command {
            fn preview(&self, known: &Known<'_>) -> Result<Preview, CommandError> {
                match self {
                    $(Command::$variant(c) => c.preview(known),)*
                }
            }

            async fn run(&self, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
                match self {
                    $(Command::$variant(c) => c.run(ctx).await,)*
                }
            }

            fn source(&self, bindings: &Bindings) -> Option<Result<Source, CommandError>> {
                match self {
                    $(Command::$variant(c) => c.source(bindings),)*
                }
            }

            fn cyclic(&self) -> bool {
                match self {
                    $(Command::$variant(c) => c.cyclic(),)*
                }
            }

            fn data_to_stdout(&self) -> bool {
                match self {
                    $(Command::$variant(c) => c.data_to_stdout(),)*
                }
            }

            fn palette_refusal(&self) -> Option<CommandError> {
                match self {
                    $(Command::$variant(c) => c.palette_refusal(),)*
                }
            }

            fn answers_offline(&self) -> bool {
                match self {
                    $(Command::$variant(c) => c.answers_offline(),)*
                }
            }

            fn offline(&self, bindings: &Bindings) -> Option<Result<Outcome, CommandError>> {
                match self {
                    $(Command::$variant(c) => c.offline(bindings),)*
                }
            }

            fn node(&self) -> Option<u8> {
                match self {
                    $(Command::$variant(c) => c.node(),)*
                }
            }
        }
    };
}

commands! {
    /// Send an NMT command to a node (0 = all): start, stop, preop, reset-node, reset-comm.
    Nmt(On<B, nmt::NmtArgs>) => nmt::Nmt;
    /// Read or write an object by SDO.
    #[command(subcommand)]
    Sdo(object::SdoCommand<B, D>) => object::Sdo;
    /// CiA 402 drive: enable, disable, quick-stop, fault-reset, status, or mode MODE.
    Drive(On<B, drive::DriveArgs>) => drive::Drive;
    /// Run a profile's procedure step by step (NAME=VALUE parameters); without PROCEDURE (or
    /// with --list), list the node's procedures.
    Run(On<B, run::command::RunArgs<D>>) => run::command::RunSpec;
    /// List the nodes on the bus with their identity.
    Scan(On<B, scan::ScanArgs>) => scan::Scan;
    /// Record the bus to a candump -l log (or pcapng).
    Record(On<B, record::RecordArgs>) => record::Record;
    /// Emergency stop: quick stop, then disable voltage, on every CiA 402 drive found powered
    /// (or the nodes named); reads each statusword back. Exit 0 only when all are confirmed.
    Stop(On<B, stop::StopArgs>) => stop::Stop;
    /// LSS master (CiA 305): switch, select, set-node, set-bitrate, activate-bitrate, store,
    /// inquire, identify, identify-unconfigured, fastscan, or assign N (fastscan + set-node).
    Lss(On<B, lss::LssArgs>) => lss::Lss;
    /// Send a raw frame in candump's compact form (`601#4041600000000000`, `123#R`,
    /// `12345678#00`): once, --count N times, or --every MS (until stopped without --count);
    /// or a transmit list: `send --list FILE [--duration MS]` (raw frames and RPDO
    /// signals by name, each on its own period).
    Send(On<B, send::SendArgs<D>>) => send::Send;
    /// Produce SYNC every --period MS (COB-ID 0x080), with the CiA 301 counter 1..N when
    /// --counter N is given; until stopped without --count.
    Sync(On<B, sync::SyncArgs>) => sync::Sync;
    /// PDOs: `pdo 2` reads every PDO's configuration; `pdo 2 map tpdo1 0x6041 0x6064 --type
    /// sync:2` remaps one (CiA 301 sequence, read back); `pdo 2 send rpdo1 Controlword=0x0F
    /// "Target velocity=500" --every 10` sends an RPDO (mapped signals not given are sent as 0).
    Pdo(On<B, pdo::command::PdoArgs<D>>) => pdo::command::Pdo;
    /// A node's configuration as a CiA 306 DCF: save it, load it back (the values that
    /// differ, PDOs remapped), or show what differs.
    #[command(subcommand)]
    Dcf(dcf::command::DcfCommand<B, D>) => dcf::Dcf;
    /// A watch list: objects polled by SDO every --every MS (`watch 2 0x6041 0x6064 3
    /// 0x6041`), one round per period, written as a text table, CSV or JSON lines.
    Watch(On<B, watch::WatchArgs<D>>) => watch::Watch;
}
