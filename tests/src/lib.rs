//! End-to-end testing of ringpod without hardware: the controller core with a simulated plant ([`plant`]) and
//! data-driven scenarios ([`scenario`], files under `tests/scenarios/`).

pub mod plant;
pub mod scenario;
