//! What a user hands the CLI: files read with a bound, CSV number tables, and numbers on the command line.

pub mod capture;
pub mod files;
pub mod numbers;
pub mod table;
