//! One file per subcommand; each reads its arguments, calls the library, prints.

pub mod bench;
pub mod config;
pub mod inspect;
pub mod merge;
pub mod montecarlo;
pub mod out_args;
pub mod reproduce;
pub mod run;
pub mod selfcal;
pub mod sweep;
