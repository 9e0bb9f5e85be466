//! The four seed drives: every worked example frame of their manuals decodes to what the
//! manual says, profiles load, procedures expand to the manuals' frame lists and run.

// Test code may unwrap: a failed unwrap is a failed test with its location.
#![allow(clippy::unwrap_used)]

mod seed_aimotor;
mod seed_aqmd2405;
mod seed_common;
mod seed_dexmart_dev;
mod seed_procedures;
mod seed_profiles;
mod seed_sdo_frames;
mod seed_syntron_ds;
