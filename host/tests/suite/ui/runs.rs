//! The Runs panel's record over HTTP, as the page sends it: the file's bytes.

use std::io::Write;
use std::net::TcpStream;
use std::time::Duration;

use serde_json::Value;

use super::workbench::{answer, Workbench};

/// POSTs `body` to `/api/run` as the page does: the status and the answer's JSON.
fn post_record(bench: &Workbench, body: &[u8]) -> (u16, Value) {
    let mut s = TcpStream::connect(&bench.addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    write!(
        s,
        "POST /api/run?token={} HTTP/1.1\r\nHost: {}\r\nContent-Type: text/csv\r\nContent-Length: {}\r\n\
         Connection: close\r\n\r\n",
        bench.token,
        bench.addr,
        body.len()
    )
    .unwrap();
    s.write_all(body).unwrap();
    let (status, answer) = answer(&mut s);
    (status, serde_json::from_str(&answer).unwrap_or(Value::Null))
}

/// 80 s at 100 Hz as `stream --record` writes it (full-precision floats, as a real record's): 2.6 MB.
fn record_80_s() -> String {
    let mut text =
        "host_s,device_s,cmd_x,cmd_y,cmd_z,cmd_alpha,cmd_beta,cmd_gamma,x,y,z,alpha,beta,gamma,steps_1,steps_2,\
                    steps_3,steps_4,steps_5,steps_6,state,limited,refused,held,applied,limited_total,refused_total,\
                    tick_cost,aux1,aux2\n"
            .to_owned();
    for i in 0..8000 {
        let t = f64::from(i) * 0.01;
        let a = 0.05 * (t * 1.3).sin() + if i == 5555 { 0.3 } else { 0.0 };
        let z = 0.2275 + 0.01 * (t * 0.7).sin();
        text += &format!(
            "{:.6},{t:.6},{},{},{z},{a},{},{},{},{},{z},{a},{},{},{},{},{},{},{},{},Running,0,0,0,{i},0,0,173,0,0\n",
            t + 0.5,
            0.001 * (t * 0.3).cos(),
            0.002 * t.sin(),
            0.03 * (t * 0.9).cos(),
            0.1 * (t * 0.2).sin(),
            0.001 * (t * 0.3).cos(),
            0.002 * t.sin(),
            0.03 * (t * 0.9).cos(),
            0.1 * (t * 0.2).sin(),
            1000 + i,
            2000 - i,
            i * 3,
            -i,
            7,
            i / 2,
        );
    }
    text
}

#[test]
fn an_evening_s_record_over_2_mb_opens_drawn_at_a_few_thousand_points() {
    let bench = Workbench::start(&[]);
    let text = record_80_s();
    // More than the 2 MiB a JSON body may have.
    assert!(text.len() > 2_200_000, "{} bytes", text.len());
    let (status, run) = post_record(&bench, text.as_bytes());
    assert_eq!(status, 200, "{run}");
    assert_eq!(run["rows"], 8000);
    let points = run["t"].as_array().unwrap().len();
    assert!((2048..=4096).contains(&points), "{points} points");
    // The one-row spike in roll is on the chart, at its height.
    let roll = run["commanded"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p[3].as_f64().unwrap());
    let peak = roll.fold(f64::MIN, f64::max);
    assert!(
        (peak - (0.3 + 0.05 * (55.55f64 * 1.3).sin())).abs() < 1e-9,
        "peak {peak}"
    );
    // What is not a record is refused in words.
    let (status, refused) = post_record(&bench, b"t,x\n0,1\n");
    assert_eq!(status, 422);
    assert!(refused["error"].as_str().unwrap().contains("no column"), "{refused}");
}
