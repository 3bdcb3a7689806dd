//! `ringpod monitor`: a live terminal view of the device from its telemetry: state, supplies and outputs, every
//! input, each axis's position, the counters and the tick cost. `q`, Esc or Ctrl-C ends it.

use std::io::Write;
use std::time::{Duration, Instant};

use ratatui::backend::{Backend, CrosstermBackend};
use ratatui::crossterm::event::{self, Event, KeyCode, KeyModifiers};
use ratatui::crossterm::terminal::{disable_raw_mode, enable_raw_mode, EnterAlternateScreen, LeaveAlternateScreen};
use ratatui::crossterm::ExecutableCommand;
use ratatui::layout::{Constraint, Direction, Layout};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph, Row, Table};
use ratatui::{Frame, Terminal};
use ringpod_core::protocol::{Telemetry, TelemetryFlags};
use ringpod_core::safety::debounce::InputBit;

use super::state_name;
use crate::link::client::{Client, ClientError, Transport};

/// What the view shows: the newest sample and how the link is doing.
#[derive(Debug, Clone, Default)]
pub struct View {
    /// The newest telemetry sample.
    pub sample: Option<Telemetry>,
    /// Samples received.
    pub received: u64,
    /// Samples per second over the last second.
    pub rate_hz: f64,
    /// Samples the client dropped.
    pub dropped: u64,
    /// Where the device is.
    pub source: String,
}

/// A label lit in `(foreground, background)` when `on`, grey otherwise.
fn lit(on: bool, label: &str, (fg, bg): (Color, Color)) -> Span<'static> {
    let style = if on {
        Style::default().fg(fg).bg(bg).add_modifier(Modifier::BOLD)
    } else {
        Style::default().fg(Color::Gray)
    };
    Span::styled(format!(" {label} "), style)
}

/// A green lamp: an output or a supply that is on.
fn lamp(on: bool, label: &str) -> Span<'static> {
    lit(on, label, (Color::Black, Color::Green))
}

/// A red lamp: something to look at.
fn alarm(active: bool, label: &str) -> Span<'static> {
    lit(active, label, (Color::White, Color::Red))
}

/// Draws the view.
pub fn draw(frame: &mut Frame, view: &View) {
    let rows = Layout::default()
        .direction(Direction::Vertical)
        .constraints([
            Constraint::Length(3),
            Constraint::Length(4),
            Constraint::Length(10),
            Constraint::Min(4),
        ])
        .split(frame.area());
    let Some(t) = view.sample else {
        let waiting = Paragraph::new(format!("waiting for telemetry from {} ...", view.source))
            .block(Block::default().borders(Borders::ALL).title(" ringpod monitor "));
        frame.render_widget(waiting, frame.area());
        return;
    };
    frame.render_widget(header(&t, view), rows[0]);
    frame.render_widget(supplies(&t), rows[1]);
    frame.render_widget(axes(&t), rows[2]);
    frame.render_widget(motion(&t), rows[3]);
}

/// The state, device time, tick cost and telemetry rate.
fn header<'a>(t: &Telemetry, view: &View) -> Paragraph<'a> {
    Paragraph::new(Line::from(vec![
        Span::styled(
            format!(" {} ", state_name(t.state)),
            Style::default().add_modifier(Modifier::BOLD | Modifier::REVERSED),
        ),
        Span::raw(format!(
            "   device time {:.2} s   tick {} {}   telemetry {:.0} Hz ({} received, {} dropped)",
            t.time_us as f64 * 1e-6,
            t.tick_cost,
            if view.source.contains("sim") { "ns" } else { "cycles" },
            view.rate_hz,
            view.received,
            view.dropped
        )),
    ]))
    .block(
        Block::default()
            .borders(Borders::ALL)
            .title(format!(" ringpod monitor: {} ", view.source)),
    )
}

/// Relays, driver enable, supply sense and the e-stop, as lamps.
fn supplies<'a>(t: &Telemetry) -> Paragraph<'a> {
    let input = |bit: InputBit| t.inputs & bit.mask() != 0;
    Paragraph::new(vec![
        Line::from(vec![
            Span::raw("relays and drivers: "),
            lamp(t.outputs & 1 != 0, "LOGIC_EN"),
            Span::raw(" "),
            lamp(t.outputs & 2 != 0, "POWER_EN"),
            Span::raw(" "),
            lamp(t.outputs & 4 != 0, "DRIVERS"),
            Span::raw("  aux: "),
            lamp(t.outputs & 8 != 0, "AUX1"),
            Span::raw(" "),
            lamp(t.outputs & 16 != 0, "AUX2"),
        ]),
        Line::from(vec![
            Span::raw("supply sense:       "),
            lamp(input(InputBit::LogicOk), "LOGIC_OK"),
            Span::raw(" "),
            lamp(input(InputBit::PowerOk), "POWER_OK"),
            Span::raw("   "),
            alarm(input(InputBit::EStop), "E-STOP OPEN"),
        ]),
    ])
    .block(Block::default().borders(Borders::ALL).title(" supplies "))
}

/// Each axis's steps and its home and end switches.
fn axes<'a>(t: &Telemetry) -> Table<'a> {
    let input = |bit: InputBit| t.inputs & bit.mask() != 0;
    Table::new(
        (0..6u8).map(|a| {
            Row::new(vec![
                format!("axis {}", a + 1),
                format!("{:>12}", t.steps[usize::from(a)]),
                if input(InputBit::Home(a)) {
                    "HOME".into()
                } else {
                    "-".into()
                },
                if input(InputBit::Limit(a)) {
                    "LIMIT".into()
                } else {
                    "-".into()
                },
            ])
        }),
        [
            Constraint::Length(8),
            Constraint::Length(14),
            Constraint::Length(6),
            Constraint::Length(6),
        ],
    )
    .header(Row::new(vec!["", "steps", "home", "end"]).style(Style::default().add_modifier(Modifier::BOLD)))
    .block(Block::default().borders(Borders::ALL).title(" axes and switches "))
}

/// The counters with their lamps, and the target pose.
fn motion<'a>(t: &Telemetry) -> Paragraph<'a> {
    let p = t.target.to_array();
    let flags = [
        (TelemetryFlags::LIMITED, "limited"),
        (TelemetryFlags::REFUSED, "refused"),
        (TelemetryFlags::HELD, "held"),
    ];
    let mut counters = vec![Span::raw(format!(
        "applied {}   limited {}   refused {}   ",
        t.applied, t.limited, t.refused
    ))];
    counters.extend(flags.iter().map(|(bit, name)| alarm(t.flags & bit != 0, name)));
    Paragraph::new(vec![
        Line::from(counters),
        Line::from(format!(
            "target: x {:+.4} y {:+.4} z {:.4} m   roll {:+.2} pitch {:+.2} yaw {:+.2} deg",
            p[0],
            p[1],
            p[2],
            p[3].to_degrees(),
            p[4].to_degrees(),
            p[5].to_degrees()
        )),
    ])
    .block(Block::default().borders(Borders::ALL).title(" motion (q: quit) "))
}

/// Why the monitor could not run or stopped.
#[derive(Debug, thiserror::Error)]
pub enum MonitorError {
    /// Its output is not a terminal.
    #[error(
        "monitor draws on a terminal, and its output is not one (`device status` or `stream --record` give the same \
         data as text)"
    )]
    NotATerminal,
    /// The device's answer.
    #[error(transparent)]
    Client(#[from] ClientError),
    /// The terminal could not be drawn on.
    #[error("terminal: {0}")]
    Terminal(#[from] std::io::Error),
}

/// Runs the view until `q`, Esc or Ctrl-C, or for `frames` redraws. Draws ten times a second.
pub fn run<T: Transport>(
    client: &mut Client<T>,
    source: &str,
    frames: Option<u64>,
    stop: &dyn Fn() -> bool,
) -> Result<(), MonitorError> {
    use std::io::IsTerminal;
    if !std::io::stdout().is_terminal() {
        return Err(MonitorError::NotATerminal);
    }
    client.hello()?;
    client.telemetry(true)?;
    let mut out = std::io::stdout();
    enable_raw_mode()?;
    out.execute(EnterAlternateScreen)?;
    let mut terminal = Terminal::new(CrosstermBackend::new(std::io::stdout()))?;
    // Whatever ends the view (q, a signal, an error), the terminal is given back as it was.
    let result = view_loop(&mut terminal, client, source, frames, stop);
    let _ = disable_raw_mode();
    let _ = out.execute(LeaveAlternateScreen);
    let _ = out.flush();
    let _ = client.telemetry(false);
    result
}

fn view_loop<B: Backend, T: Transport>(
    terminal: &mut Terminal<B>,
    client: &mut Client<T>,
    source: &str,
    frames: Option<u64>,
    stop: &dyn Fn() -> bool,
) -> Result<(), MonitorError> {
    let mut view = View {
        source: source.to_owned(),
        ..View::default()
    };
    let mut window: Vec<Instant> = Vec::new();
    let mut drawn = 0u64;
    while !stop() {
        client.transport().elapse(Duration::from_millis(100));
        let samples = client.take_telemetry()?;
        let now = Instant::now();
        window.extend(std::iter::repeat_n(now, samples.len()));
        window.retain(|t| now.duration_since(*t) < Duration::from_secs(1));
        view.rate_hz = window.len() as f64;
        view.received += samples.len() as u64;
        view.dropped = client.telemetry_dropped;
        if let Some(last) = samples.last() {
            view.sample = Some(*last);
        }
        terminal.draw(|f| draw(f, &view))?;
        drawn += 1;
        if frames.is_some_and(|n| drawn >= n) {
            return Ok(());
        }
        if event::poll(Duration::ZERO)? {
            if let Event::Key(k) = event::read()? {
                let ctrl_c = k.code == KeyCode::Char('c') && k.modifiers.contains(KeyModifiers::CONTROL);
                if ctrl_c || matches!(k.code, KeyCode::Char('q') | KeyCode::Esc) {
                    return Ok(());
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratatui::backend::TestBackend;
    use ringpod_core::kinematics::Pose;
    use ringpod_core::safety::State;

    fn text(view: &View) -> String {
        let mut terminal = Terminal::new(TestBackend::new(100, 24)).unwrap();
        terminal.draw(|f| draw(f, view)).unwrap();
        let buffer = terminal.backend().buffer().clone();
        buffer.content().iter().map(|c| c.symbol()).collect::<String>()
    }

    #[test]
    fn the_view_shows_state_inputs_positions_and_counters() {
        let sample = Telemetry {
            time_us: 12_340_000,
            state: State::Running,
            pose: Pose::new(0.0, 0.0, 0.227, 0.0, 0.0, 0.0),
            target: Pose::new(0.01, 0.0, 0.227, 0.0, 0.0, 0.5),
            steps: [101, 202, 303, 404, -505, 606],
            flags: TelemetryFlags::LIMITED,
            applied: 77,
            limited: 5,
            refused: 1,
            tick_cost: 5600,
            inputs: InputBit::Home(2).mask() | InputBit::LogicOk.mask() | InputBit::EStop.mask(),
            outputs: 0b111,
        };
        let view = View {
            sample: Some(sample),
            received: 10,
            rate_hz: 100.0,
            dropped: 0,
            source: "/dev/ttyACM0".into(),
        };
        let screen = text(&view);
        for want in [
            "Running",
            "device time 12.34 s",
            "LOGIC_EN",
            "E-STOP OPEN",
            "-505",
            "HOME",
            "applied 77",
            "limited 5",
            "yaw +28.65 deg",
        ] {
            assert!(screen.contains(want), "{want:?} missing from the screen");
        }
        assert_eq!(screen.matches("HOME").count(), 1, "only axis 3's home switch is active");
        let waiting = text(&View {
            source: "sim".into(),
            ..View::default()
        });
        assert!(waiting.contains("waiting for telemetry"));
    }
}
