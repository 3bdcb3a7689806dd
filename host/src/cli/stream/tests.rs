use clap::Parser;

use crate::cli::{Cli, Command};
use crate::stream::command::Input;

fn parse(args: &[&str]) -> Result<Box<super::StreamArgs>, clap::Error> {
    let cli = Cli::try_parse_from(["ringpod", "stream", "--sim"].iter().chain(args))?;
    match cli.command {
        Command::Stream(args) => Ok(args),
        _ => unreachable!("a stream command"),
    }
}

/// The game, its cueing file and the capture reach the job; the UDP options do not go with it.
#[cfg(windows)]
#[test]
fn telemetry_shm_becomes_a_shared_memory_job() {
    use crate::games::shm::Game;
    let args = parse(&[
        "--telemetry-shm",
        "rf2",
        "--cue-config",
        "c.toml",
        "--capture",
        "x.pcap",
        "--udp-idle",
        "9",
    ])
    .unwrap();
    let job = args.job().unwrap();
    assert!(matches!(
        &job.input,
        Input::Shm { game: Game::Rf2, cue_config: Some(c), profile: None, idle, lap_preview: true } if c.as_os_str() == "c.toml" && *idle == 9.0
    ));
    assert!(job.capture.is_some());
    for other in [
        &["--udp-from", "127.0.0.1"][..],
        &["--outsim-opts", "ff"],
        &["--telemetry-udp", "127.0.0.1:0"],
    ] {
        assert!(
            parse(&[&["--telemetry-shm", "ac"][..], other].concat()).is_err(),
            "{other:?}"
        );
    }
}

/// Off Windows: a usage error naming the option and why.
#[cfg(not(windows))]
#[test]
fn telemetry_shm_is_refused_by_name_off_windows() {
    let e = parse(&["--telemetry-shm", "ac"]).err().unwrap();
    assert_eq!(e.kind(), clap::error::ErrorKind::ValueValidation);
    assert_eq!(e.exit_code(), 2);
    let text = e.to_string();
    assert!(text.contains("--telemetry-shm") && text.contains("Windows"), "{text}");
}

/// The cueing file goes with either telemetry source, and with no other; LFS's `OutSim Opts` only with UDP telemetry.
#[test]
fn a_cueing_file_needs_a_telemetry_source() {
    for source in [
        &["--motion", "demo"][..],
        &["--udp", "127.0.0.1:0"],
        &["--input", "x.csv"],
    ] {
        assert!(
            parse(&[source, &["--outsim-opts", "ff"]].concat()).is_err(),
            "{source:?}"
        );
    }
    assert!(parse(&["--telemetry-udp", "127.0.0.1:0", "--outsim-opts", "ff"]).is_ok());
    assert!(parse(&["--telemetry-udp", "127.0.0.1:0", "--cue-config", "c.toml"]).is_ok());
    assert!(parse(&["--udp", "127.0.0.1:0", "--cue-config", "c.toml"]).is_err());
    let args = parse(&["--telemetry-udp", "127.0.0.1:0"]).unwrap();
    assert!(matches!(args.job().unwrap().input, Input::Udp { .. }));
}

#[test]
fn outsim_options_need_a_format_that_reads_outsim2() {
    use crate::cli::requests::RequestError;
    for (format, reads) in [
        ("text", false),
        ("outsim", false),
        ("f1", false),
        ("forza", false),
        ("beamng", false),
        ("outsim2", true),
        ("auto", true),
    ] {
        let args = parse(&[
            "--telemetry-udp",
            "127.0.0.1:0",
            "--telemetry-format",
            format,
            "--outsim-opts",
            "ff",
        ]);
        match args.unwrap().job() {
            Ok(_) => assert!(reads, "{format}: taken"),
            Err(RequestError::OutsimOptsFormat) => assert!(!reads, "{format}: refused"),
            Err(e) => panic!("{format}: {e}"),
        }
    }
}

/// `--lap-preview` is on unless `off`, reaches the telemetry job, and goes only with a telemetry source.
#[test]
fn the_lap_preview_is_on_unless_off_and_only_for_telemetry() {
    use crate::stream::command::Datagrams;
    let preview = |extra: &[&str]| {
        let args = parse(&[&["--telemetry-udp", "127.0.0.1:0"][..], extra].concat()).unwrap();
        match args.job().unwrap().input {
            Input::Udp {
                holds: Datagrams::Telemetry { lap_preview, .. },
                ..
            } => lap_preview,
            _ => panic!("a telemetry job"),
        }
    };
    assert!(preview(&[]));
    assert!(preview(&["--lap-preview", "on"]));
    assert!(!preview(&["--lap-preview", "off"]));
    assert!(parse(&["--telemetry-udp", "127.0.0.1:0", "--lap-preview", "maybe"]).is_err());
    assert!(parse(&["--udp", "127.0.0.1:0", "--lap-preview", "off"]).is_err());
    assert!(parse(&["--motion", "sine", "--lap-preview", "on"]).is_err());
    assert!(parse(&["--motion", "sine"]).is_ok(), "the default needs no telemetry");
}
