//! Games' telemetry packets written field by field from their publishers' layouts (each layout and its source is
//! in the decoder's module, `host/src/games/`). One copy for two users: the decoders' unit tests include this file
//! (`#[path]` in `host/src/games/mod.rs`) and the end-to-end tests through `common`, so both send the same bytes.
//! Only `std` here: the file is compiled into both crates.

// Each crate that includes this uses a part of it.
#![allow(dead_code)]

/// A little-endian packet written field by field.
#[derive(Default)]
pub struct Writer(pub Vec<u8>);

impl Writer {
    pub fn bytes(&mut self, b: &[u8]) -> &mut Self {
        self.0.extend_from_slice(b);
        self
    }
    pub fn f32(&mut self, v: f32) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }
    pub fn f32s(&mut self, v: &[f32]) -> &mut Self {
        v.iter().for_each(|x| {
            self.f32(*x);
        });
        self
    }
    pub fn u32(&mut self, v: u32) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }
    pub fn i32(&mut self, v: i32) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }
    pub fn u16(&mut self, v: u16) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }
    pub fn i16(&mut self, v: i16) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }
    pub fn u8(&mut self, v: u8) -> &mut Self {
        self.bytes(&[v])
    }
    pub fn zeros(&mut self, n: usize) -> &mut Self {
        self.0.resize(self.0.len() + n, 0);
        self
    }
}

/// Live for Speed's classic OutSim packet and the `OSMain` section `OutSimPack2` repeats.
pub mod outsim {
    use super::Writer;

    /// `OutSimMain` (60 bytes) as LFS lays it out: angular velocity, heading, pitch, roll, acceleration (world
    /// axes), velocity and position zero.
    pub fn main_section(w: &mut Writer, ang_vel: [f32; 3], hpr: [f32; 3], accel: [f32; 3]) {
        w.f32s(&ang_vel).f32s(&hpr).f32s(&accel).f32s(&[0.0; 3]).zeros(12);
    }

    /// The classic packet: time (ms), `OSMain`, and the `OutSim ID` 7 when `id`.
    pub fn packet(time_ms: u32, ang_vel: [f32; 3], hpr: [f32; 3], accel: [f32; 3], id: bool) -> Vec<u8> {
        let mut w = Writer::default();
        w.u32(time_ms);
        main_section(&mut w, ang_vel, hpr, accel);
        if id {
            w.i32(7);
        }
        assert_eq!(w.0.len(), if id { 68 } else { 64 });
        w.0
    }
}

/// Live for Speed's `OutSimPack2`.
pub mod outsim2 {
    use super::Writer;

    /// A packet as LFS writes it for `OutSim Opts` = `opts`, every section field by field in LFS's order: the
    /// given time and motion, ID 42, and non-zero filler in the other sections (so that a misplaced section shows).
    pub fn packet(opts: u16, time_ms: u32, ang_vel: [f32; 3], hpr: [f32; 3], accel: [f32; 3]) -> Vec<u8> {
        let has = |bit: u16| opts & bit != 0;
        let mut w = Writer::default();
        if has(0x01) {
            w.bytes(b"LFST");
        }
        if has(0x02) {
            w.i32(42);
        }
        if has(0x04) {
            w.u32(time_ms);
        }
        if has(0x08) {
            super::outsim::main_section(&mut w, ang_vel, hpr, accel);
        }
        if has(0x10) {
            w.f32s(&[0.8, 0.1, -0.2, 0.0, 0.0]);
        }
        if has(0x20) {
            w.u8(3).zeros(3).f32(600.0).f32(300.0);
        }
        if has(0x40) {
            w.f32(1234.0).f32(1230.0);
        }
        if has(0x80) {
            for _ in 0..4 {
                w.f32s(&[0.05, 0.01, 100.0, 200.0, 3000.0, 50.0, 0.0])
                    .bytes(&[20, 0, 1, 0])
                    .f32(0.02)
                    .f32(0.01);
            }
        }
        if has(0x100) {
            w.f32(12.0).f32(0.0);
        }
        w.0
    }
}

/// BeamNG's MotionSim packet.
pub mod beamng {
    use super::Writer;

    /// A packet field by field: acceleration (car axes), up vector, roll/pitch/yaw and their rates.
    pub fn packet(acc: [f32; 3], up: [f32; 3], rpy: [f32; 3], rates: [f32; 3]) -> Vec<u8> {
        let mut w = Writer::default();
        w.bytes(b"BNG1").f32s(&[100.0, -20.0, 5.0]).f32s(&[0.0, 15.0, 0.0]);
        w.f32s(&acc).f32s(&up).f32s(&rpy).f32s(&rates).f32s(&[0.0; 3]);
        assert_eq!(w.0.len(), 88);
        w.0
    }
}

/// Codemasters' extradata 3.
pub mod codemasters {
    use super::Writer;

    /// A packet written channel by channel as extradata 3 lists them: total time (s), the car's right and forward
    /// unit vectors (world, y up) and its g-forces, everything else plausible.
    pub fn packet(time: f32, right: [f32; 3], forward: [f32; 3], g_lat: f32, g_long: f32) -> Vec<u8> {
        on_lap(time, 800.0, right, forward, g_lat, g_long)
    }

    /// A packet as [`packet`]'s, `lap_distance` metres into the lap (and as far into the session).
    pub fn on_lap(
        time: f32,
        lap_distance: f32,
        right: [f32; 3],
        forward: [f32; 3],
        g_lat: f32,
        g_long: f32,
    ) -> Vec<u8> {
        let mut w = Writer::default();
        // Total time, lap time, lap distance, total distance.
        w.f32s(&[time, 35.0, lap_distance, lap_distance]);
        w.f32s(&[10.0, 1.0, 20.0]).f32(25.0).f32s(&[0.0, 0.0, 25.0]); // position, speed, velocity
        w.f32s(&right).f32s(&forward);
        w.f32s(&[0.0; 4]).f32s(&[0.0; 4]).f32s(&[25.0; 4]); // suspension position, velocity, wheel speed
        w.f32s(&[1.0, 0.0, 0.0, 0.0, 3.0]); // throttle, steer, brake, clutch, gear
        w.f32(g_lat).f32(g_long);
        w.f32s(&[
            0.0, 600.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 40.0, 60.0, 0.0, 1.0, 0.0, 0.0,
        ]);
        w.f32s(&[300.0; 4]).f32s(&[25.0; 4]); // brake temperatures, tyre pressures
        w.f32s(&[0.0, 1.0, 5000.0, 0.0, 800.0, 90.0, 6.0]); // team, laps, track size, last lap, max/idle rpm, gears
        assert_eq!(w.0.len(), 264);
        w.0
    }
}

/// EA SPORTS F1 23 to 25: the motion packet.
pub mod f1 {
    use super::Writer;

    /// One car's `CarMotionData`: forward and right unit vectors (world, y up), g-forces (lateral, longitudinal,
    /// vertical).
    fn car(w: &mut Writer, forward: [f32; 3], right: [f32; 3], g_lat_long_vert: [f32; 3]) {
        w.f32s(&[100.0, 2.0, -50.0]).f32s(&[10.0, 0.0, 0.0]);
        for v in forward.iter().chain(&right) {
            w.i16((v * 32767.0).round() as i16);
        }
        w.f32s(&g_lat_long_vert).f32s(&[0.1, 0.0, 0.0]);
    }

    /// The `PacketHeader` (29 bytes): format, game year, version 1.05, packet version 1, `id`, a session, `time`,
    /// frame 3000, the player in slot `player`, no second player.
    fn header(format: u16, id: u8, player: u8, time: f32) -> Writer {
        let mut w = Writer::default();
        w.u16(format).u8((format - 2000) as u8).u8(1).u8(5).u8(1).u8(id);
        w.bytes(&0x1234_5678_9abc_def0u64.to_le_bytes())
            .f32(time)
            .u32(3000)
            .u32(3000)
            .u8(player)
            .u8(255);
        assert_eq!(w.0.len(), 29);
        w
    }

    /// A packet of `format` (2023..2025) and id `id` at session time `time` (s), laid out as the motion packet
    /// with the player in slot `player`, every other car level and braking hard (so that reading the wrong car
    /// shows).
    pub fn packet(
        format: u16,
        id: u8,
        player: u8,
        time: f32,
        forward: [f32; 3],
        right: [f32; 3],
        g: [f32; 3],
    ) -> Vec<u8> {
        let mut w = header(format, id, player, time);
        for i in 0..22u8 {
            if i == player {
                car(&mut w, forward, right, g);
            } else {
                car(&mut w, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, -4.0, 0.0]);
            }
        }
        assert_eq!(w.0.len(), 1349);
        w.0
    }

    /// The lap data packet (id 2) of `format` at session time `time`, every car's `LapData` field by field as the
    /// specification lists them (F1 23: 50 bytes, the time deltas in ms; F1 24 and 25: 57 bytes, each delta split
    /// into its ms and minutes parts, and the speed trap's fastest speed and lap at the end): the player in slot
    /// `player` at `lap_distance` m, every other car at 1234.5 m (so that reading the wrong car shows).
    pub fn lap_data(format: u16, player: u8, time: f32, lap_distance: f32) -> Vec<u8> {
        let mut w = header(format, 2, player, time);
        for i in 0..22u8 {
            let d = if i == player { lap_distance } else { 1234.5 };
            // Last and current lap time (ms), sector 1 and 2 (ms and minutes parts).
            w.u32(90_000).u32(30_000).u16(25_000).u8(0).u16(28_000).u8(0);
            if format == 2023 {
                w.u16(500).u16(1500); // to the car in front, to the leader (ms)
            } else {
                w.u16(500).u8(0).u16(1500).u8(0);
            }
            w.f32(d).f32(d + 10_000.0).f32(0.0); // lap distance, total distance, safety car delta
            w.u8(i + 1).u8(3); // car position, current lap number
                               // Pit status, pit stops, sector, lap invalid, penalties, warnings, corner cutting warnings, unserved
                               // drive through and stop go penalties, grid position, driver status, result status, pit lane timer.
            w.bytes(&[0, 0, 1, 0, 0, 0, 0, 0, 0, i + 1, 4, 2, 0]);
            w.u16(0).u16(0).u8(0); // pit lane time, pit stop time, should serve penalty
            if format != 2023 {
                w.f32(310.0).u8(2); // speed trap fastest speed (km/h) and lap
            }
        }
        w.u8(255).u8(255); // time trial PB and rival car
        assert_eq!(w.0.len(), if format == 2023 { 1131 } else { 1285 });
        w.0
    }

    /// The packet ids other than motion (0) that each format sends, with their sizes in bytes: EA's "F1 23 UDP
    /// Specification", "F1 24 UDP Specification" and the "C++ structures for F1 25 UDP specification" (each
    /// packet's heading, "Size: N bytes"): session, lap data, event, participants, car setups, car telemetry,
    /// car status, final classification, lobby info, car damage, session history, tyre sets, extended motion,
    /// and from F1 24 time trial, from F1 25 lap positions.
    pub fn other_ids(format: u16) -> &'static [(u8, usize)] {
        match format {
            2023 => &[
                (1, 644),
                (2, 1131),
                (3, 45),
                (4, 1306),
                (5, 1107),
                (6, 1352),
                (7, 1239),
                (8, 1020),
                (9, 1218),
                (10, 953),
                (11, 1460),
                (12, 231),
                (13, 217),
            ],
            2024 => &[
                (1, 753),
                (2, 1285),
                (3, 45),
                (4, 1350),
                (5, 1133),
                (6, 1352),
                (7, 1239),
                (8, 1020),
                (9, 1306),
                (10, 953),
                (11, 1460),
                (12, 231),
                (13, 237),
                (14, 101),
            ],
            _ => &[
                (1, 753),
                (2, 1285),
                (3, 45),
                (4, 1284),
                (5, 1133),
                (6, 1352),
                (7, 1239),
                (8, 1042),
                (9, 954),
                (10, 1041),
                (11, 1460),
                (12, 231),
                (13, 273),
                (14, 101),
                (15, 1131),
            ],
        }
    }

    /// Another packet type of `format`: the `PacketHeader` field by field (player in slot 3, no second player),
    /// then the packet's body at its specified size: the event's string code ("SSTA", session started), otherwise
    /// zeros (ringpod reads no field of the body, only the header's id).
    pub fn other(format: u16, id: u8, time: f32) -> Vec<u8> {
        let (_, size) = *other_ids(format)
            .iter()
            .find(|(i, _)| *i == id)
            .unwrap_or_else(|| panic!("no packet id {id} in format {format}"));
        let mut w = header(format, id, 3, time);
        if id == 3 {
            w.bytes(b"SSTA");
        }
        w.0.resize(size, 0);
        w.0
    }
}

/// Forza's Data Out.
pub mod forza {
    use super::Writer;

    /// Sled.
    pub const SLED: usize = 232;
    /// Forza Motorsport 7 Dash.
    pub const DASH_FM7: usize = 311;
    /// Forza Horizon 4 and 5.
    pub const HORIZON: usize = 324;
    /// Forza Motorsport (2023) Dash.
    pub const DASH_FM2023: usize = 331;

    /// The Sled fields: race on, the time (ms), the car's acceleration, angular velocity and attitude (yaw, pitch,
    /// roll), the wheel arrays and the car's identity.
    fn sled(w: &mut Writer, race_on: i32, time_ms: u32, accel: [f32; 3], ang_vel: [f32; 3], ypr: [f32; 3]) {
        w.i32(race_on).u32(time_ms).f32s(&[8000.0, 900.0, 4000.0]);
        w.f32s(&accel).f32s(&[0.0, 0.0, 20.0]).f32s(&ang_vel).f32s(&ypr);
        // Normalised suspension travel, slip ratio, wheel rotation speed.
        w.f32s(&[0.5; 4]).f32s(&[0.0; 4]).f32s(&[60.0; 4]);
        // On rumble strip (s32), puddle depth, surface rumble, slip angle, combined slip, suspension travel (m).
        (0..4).for_each(|_| {
            w.i32(0);
        });
        w.f32s(&[0.0; 4])
            .f32s(&[0.0; 4])
            .f32s(&[0.0; 4])
            .f32s(&[0.0; 4])
            .f32s(&[0.05; 4]);
        // Car ordinal, class, performance index, drivetrain, cylinders.
        w.i32(2352).i32(5).i32(800).i32(1).i32(8);
        assert_eq!(w.0.len(), SLED);
    }

    /// The Dash fields of FM7 (79 bytes): position, speed, power, torque, tyre temperatures, then boost, fuel,
    /// `DistanceTraveled` (`distance`), best, last and current lap, race time, `LapNumber` (`lap`), race position,
    /// the inputs, gear, steer and driving line.
    fn dash(w: &mut Writer, distance: f32, lap: u16) {
        w.f32s(&[1.0, 2.0, 3.0]).f32s(&[20.0, 1e5, 300.0]).f32s(&[80.0; 4]);
        w.f32s(&[0.0, 40.0, distance, 90.0, 91.0, 30.0, 300.0]);
        w.u16(lap).u8(1).u8(255).u8(0).u8(0).u8(0).u8(4).bytes(&[0, 0, 0]);
    }

    /// A packet of `size` (one of the four) with the given motion.
    pub fn packet(
        size: usize,
        race_on: i32,
        time_ms: u32,
        accel: [f32; 3],
        ang_vel: [f32; 3],
        ypr: [f32; 3],
    ) -> Vec<u8> {
        on_lap(size, race_on, time_ms, accel, ang_vel, ypr, (1500.0, 3))
    }

    /// A packet as [`packet`]'s, its Dash fields at `DistanceTraveled` and `LapNumber` `(distance, lap)`.
    pub fn on_lap(
        size: usize,
        race_on: i32,
        time_ms: u32,
        accel: [f32; 3],
        ang_vel: [f32; 3],
        ypr: [f32; 3],
        (distance, lap): (f32, u16),
    ) -> Vec<u8> {
        let mut w = Writer::default();
        sled(&mut w, race_on, time_ms, accel, ang_vel, ypr);
        match size {
            SLED => {}
            DASH_FM7 => dash(&mut w, distance, lap),
            HORIZON => {
                w.zeros(12);
                dash(&mut w, distance, lap);
                w.zeros(1);
            }
            DASH_FM2023 => {
                dash(&mut w, distance, lap);
                w.f32s(&[0.1; 4]).i32(110);
            }
            _ => panic!("Forza sends no packet of {size} bytes"),
        }
        assert_eq!(w.0.len(), size);
        w.0
    }
}

/// X-Plane's `DATA` packet.
pub mod xplane {
    use super::Writer;

    /// One record: the data set's index and its 8 values.
    pub fn record(w: &mut Writer, index: i32, values: [f32; 8]) {
        w.i32(index).f32s(&values);
    }

    /// A packet with data sets 1 (times: real time `time`), 4 (g-loads: normal, axial, side), 3 (speeds, not
    /// read), 16 (Q, P, R) when `with_rates`, and 17 (attitude, not read), in X-Plane's order.
    pub fn packet(time: f32, g_loads: [f32; 3], qpr: [f32; 3], with_rates: bool) -> Vec<u8> {
        let mut w = Writer::default();
        w.bytes(b"DATA").u8(b'*');
        record(&mut w, 1, [time, 700.0, 300.0, 0.0, -999.0, 43200.0, 50400.0, 12.0]);
        record(&mut w, 3, [120.0, 118.0, 121.0, 139.0, -999.0, 138.0, 159.0, 160.0]);
        let [n, a, s] = g_loads;
        record(&mut w, 4, [0.2, -999.0, 0.0, -999.0, n, a, s, -999.0]);
        if with_rates {
            let [q, p, r] = qpr;
            record(&mut w, 16, [q, p, r, -999.0, -999.0, -999.0, -999.0, -999.0]);
        }
        record(&mut w, 17, [2.0, 0.0, 90.0, 88.0, -999.0, -999.0, -999.0, -999.0]);
        w.0
    }
}
