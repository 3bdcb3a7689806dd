//! What a user hands the CLI: files read with a bound, CSV number tables, cueing files, and numbers on the
//! command line.

pub mod capture;
pub mod cueing;
pub mod files;
pub mod numbers;
pub mod table;
pub mod unreadable;
