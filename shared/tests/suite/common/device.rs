//! A controller as a host finds it: made with the trainer model and greeted with a matching hello. For the tests
//! that talk to the controller through requests (`#[path]`-included, so that the other tests do not carry it).

use ringpod_core::controller::{Controller, ControllerConfig};
use ringpod_core::protocol::{DeviceMessage, HostMessage, Request, PROTOCOL_VERSION};

/// The trainer model's controller after a successful hello.
pub fn connected() -> Controller {
    let mut c = Controller::new(ControllerConfig::trainer_model()).unwrap();
    let hello = c.handle(&Request {
        id: 1,
        body: HostMessage::Hello {
            version: PROTOCOL_VERSION,
        },
    });
    assert!(matches!(hello.body, DeviceMessage::Hello { .. }));
    c
}
