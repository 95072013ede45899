//! Helpers shared by the test modules that drive the `flicker` binary, and
//! a reader for the SVG charts it draws.

use std::path::Path;
use std::process::{Command, Output};

use flicker::engine::{EventRecord, Observer};
use serde_json::Value;

/// An event as the in-process tests check it.
#[derive(Debug, Clone, PartialEq)]
pub struct Seen {
    pub t: f64,
    pub guard: String,
    pub mode_before: String,
    pub mode_after: String,
    pub before: Vec<f64>,
    pub after: Vec<f64>,
}

/// Keeps every event of a run, with its modes.
#[derive(Default)]
pub struct EventLog(pub Vec<Seen>);

impl Observer for EventLog {
    fn on_event(&mut self, e: &EventRecord) -> std::io::Result<()> {
        self.0.push(Seen {
            t: e.t,
            guard: e.guard.into(),
            mode_before: e.mode_before.into(),
            mode_after: e.mode_after.into(),
            before: e.before.to_vec(),
            after: e.after.to_vec(),
        });
        Ok(())
    }
}

/// A command that runs the binary: under `FLICKER_TEST_RUNNER` where that
/// is set (an emulator, for a build for another processor: `qemu-aarch64
/// -L /usr/aarch64-linux-gnu`, see `.ci/aarch64`).
pub fn command() -> Command {
    let binary = env!("CARGO_BIN_EXE_flicker");
    let runner = std::env::var("FLICKER_TEST_RUNNER").unwrap_or_default();
    let mut words = runner.split_whitespace();
    match words.next() {
        Some(program) => {
            let mut command = Command::new(program);
            command.args(words).arg(binary);
            command
        }
        None => Command::new(binary),
    }
}

/// Run the binary with `args` and collect what it did.
pub fn flicker(args: &[&str]) -> Output {
    command().args(args).output().expect("the binary runs")
}

/// The path of a bundled scene in `models/`.
pub fn models(name: &str) -> String {
    format!("{}/models/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// A reference computed outside flicker, `tests/fixtures/NAME`, parsed.
pub fn fixture(name: &str) -> Value {
    read_json(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures")
            .join(name),
    )
}

/// A fixture's number, written as a string to keep its digits.
pub fn digits(v: &Value) -> f64 {
    v.as_str().unwrap().parse().unwrap()
}

/// A JSON file, parsed.
pub fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// What a plotters SVG chart draws, read back: its tick labels place values
/// on the pixel axes, so its polylines turn back into data.
pub struct SvgChart {
    text: String,
    /// `pixel = offset + slope * value` for x and for y.
    x_axis: (f64, f64),
    y_axis: (f64, f64),
}

/// `name="value"` of an SVG element's attributes.
fn attribute<'a>(element: &'a str, name: &str) -> Option<&'a str> {
    let start = element.find(&format!(" {name}=\""))? + name.len() + 3;
    Some(&element[start..start + element[start..].find('"')?])
}

/// Least-squares `pixel = offset + slope * value` through the ticks; no
/// tick may sit more than a pixel off it (positions are whole pixels).
fn axis(ticks: &[(f64, f64)]) -> (f64, f64) {
    assert!(ticks.len() >= 3, "ticks {ticks:?}");
    let n = ticks.len() as f64;
    let (mv, mp) = ticks
        .iter()
        .fold((0.0, 0.0), |(a, b), (v, p)| (a + v / n, b + p / n));
    let svv: f64 = ticks.iter().map(|(v, _)| (v - mv).powi(2)).sum();
    let svp: f64 = ticks.iter().map(|(v, p)| (v - mv) * (p - mp)).sum();
    let slope = svp / svv;
    let offset = mp - slope * mv;
    for (v, p) in ticks {
        assert!((offset + slope * v - p).abs() <= 1.0, "tick {v} at {p}");
    }
    (offset, slope)
}

impl SvgChart {
    pub fn read(path: &Path) -> Self {
        let text = std::fs::read_to_string(path).unwrap();
        let (mut xs, mut ys) = (Vec::new(), Vec::new());
        for piece in text.split("<text").skip(1) {
            let (element, rest) = piece.split_once('>').unwrap();
            let content = rest.split("</text>").next().unwrap().trim();
            let Ok(value) = content.parse::<f64>() else {
                continue;
            };
            let at = |name| attribute(element, name).unwrap().parse::<f64>().unwrap();
            // Tick labels: below the x axis (top-aligned, centred), left
            // of the y axis (centred on the tick, right-aligned).
            match (attribute(element, "dy"), attribute(element, "text-anchor")) {
                (Some("0.76em"), Some("middle")) => xs.push((value, at("x"))),
                (Some("0.5ex"), Some("end")) => ys.push((value, at("y"))),
                _ => {}
            }
        }
        SvgChart {
            x_axis: axis(&xs),
            y_axis: axis(&ys),
            text,
        }
    }

    /// The points, in pixels, of the polylines drawn in `stroke` (`#RRGGBB`)
    /// at `width`, in drawing order.
    pub fn polylines(&self, stroke: &str, width: &str) -> Vec<Vec<(f64, f64)>> {
        self.text
            .split("<polyline")
            .skip(1)
            .map(|piece| piece.split_once("/>").unwrap().0)
            .filter(|e| attribute(e, "stroke") == Some(stroke))
            .filter(|e| attribute(e, "stroke-width") == Some(width))
            .map(|e| {
                attribute(e, "points")
                    .unwrap()
                    .split_whitespace()
                    .map(|p| {
                        let (x, y) = p.split_once(',').unwrap();
                        (x.parse().unwrap(), y.parse().unwrap())
                    })
                    .collect()
            })
            .collect()
    }

    /// The pixel at which the chart draws the data point `(x, y)`.
    pub fn pixel(&self, (x, y): (f64, f64)) -> (f64, f64) {
        (
            self.x_axis.0 + self.x_axis.1 * x,
            self.y_axis.0 + self.y_axis.1 * y,
        )
    }

    /// The data point the chart draws at the pixel `(x, y)`.
    pub fn value(&self, (x, y): (f64, f64)) -> (f64, f64) {
        (
            (x - self.x_axis.0) / self.x_axis.1,
            (y - self.y_axis.0) / self.y_axis.1,
        )
    }

    /// The data values one pixel spans on each axis.
    pub fn pixel_size(&self) -> (f64, f64) {
        (1.0 / self.x_axis.1.abs(), 1.0 / self.y_axis.1.abs())
    }
}

/// A chain of 10 units that impacts (strains and velocities set apart,
/// load 1.3 after the release) to `t_end`: the tools' test chain.
pub fn ten_unit_chain(t_end: f64) -> Value {
    serde_json::json!({
        "model": "chain", "units": 10, "length": 10.0, "wave_speed": 1.0,
        "load": {"before": 1.0, "after": 1.3}, "constraint": true,
        "initial": {
            "strain": [0.3, 0.1, 0.25, 0.05, 0.2, 0.3, 0.1, 0.15, 0.05, 0.2],
            "velocity": [0.1, -0.2, 0.0, 0.3, -0.1, 0.0, 0.2, -0.3, 0.1, 0.0]
        },
        "t_end": t_end
    })
}
