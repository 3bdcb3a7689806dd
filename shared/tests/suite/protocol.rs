//! Every message fits a frame at its largest encoding.

use ringpod_core::kinematics::{Check, Pose};
use ringpod_core::motion::{LimitCounters, LimitReport, RejectCounters};
use ringpod_core::protocol::{self, DeviceMessage, Response, Status, MAX_FRAME, MAX_PAYLOAD};
use ringpod_core::safety::{FaultReason, State, Supplies};

#[test]
fn the_largest_status_fits_a_frame() {
    let big = Pose::new(f32::MAX, f32::MIN, f32::MAX, f32::MIN, f32::MAX, f32::MIN);
    let status = Status {
        state: State::Fault(FaultReason::Limit(u8::MAX), Supplies::Both),
        homed: true,
        aux: u8::MAX,
        steps: [i64::MIN, i64::MAX, i64::MIN, i64::MAX, i64::MIN, i64::MAX],
        pose: big,
        target: big,
        applied: u32::MAX,
        limited: LimitCounters {
            count: u32::MAX,
            by_check: [u32::MAX; 6],
            largest_translation: f32::MAX,
            largest_rotation: f32::MAX,
            edge_ticks: u32::MAX,
            actuator_ticks: u32::MAX,
        },
        rejected: RejectCounters {
            non_finite: u32::MAX,
            unreachable: u32::MAX,
            gross_jump: u32::MAX,
            stale: u32::MAX,
            not_streaming: u32::MAX,
        },
        held: u32::MAX,
        carried: u32::MAX,
        bad_frames: u32::MAX,
        tick_cost: u32::MAX,
        queue_depth: u16::MAX,
        idle_periods: u32::MAX,
        passed_periods: u32::MAX,
        spare_steps: [i64::MIN, i64::MAX],
    };
    let response = Response {
        id: u32::MAX,
        body: DeviceMessage::Status(status),
    };
    let mut buf = [0u8; 1024];
    let payload = postcard::to_slice(&response, &mut buf).unwrap();
    assert!(payload.len() <= MAX_PAYLOAD, "{} bytes", payload.len());
    let mut frame = [0u8; MAX_FRAME];
    let n = protocol::encode(&response, &mut frame).unwrap();
    assert_eq!(protocol::decode::<Response>(&frame[..n - 1]).unwrap(), response);
    let limited = Response {
        id: u32::MAX,
        body: DeviceMessage::Limited(LimitReport {
            check: Check::Stability,
            translation: f32::MAX,
            rotation: f32::MAX,
        }),
    };
    assert!(protocol::encode(&limited, &mut frame).is_ok());
}
