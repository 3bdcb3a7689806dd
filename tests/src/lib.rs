//! End-to-end tests of ringpod (grow with the host CLI and QEMU issues).
