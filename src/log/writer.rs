//! Streams events to a JSON Lines file as the run goes.
//!
//! Lines are formatted by hand (shortest round-trip numbers via `ryu` and `itoa`) into a
//! buffer that is written out only in whole lines, so the hot loop does no
//! allocation and a cut-off file still ends at a line boundary.

use std::io::{self, Write};

use crate::engine::{EventRecord, Label, Name, Observer};

/// Bytes collected before they are written out.
const CHUNK: usize = 1 << 16;

/// An [`Observer`] that writes each event as one line of `events.jsonl`
/// to `out`, in chunks of whole lines. Call [`JsonlWriter::flush`] at the
/// end for the last of them.
pub struct JsonlWriter<W: Write> {
    out: W,
    buffer: Vec<u8>,
    floats: ryu::Buffer,
    integers: itoa::Buffer,
}

impl<W: Write> JsonlWriter<W> {
    /// A writer to `out`, with nothing written yet.
    pub fn new(out: W) -> Self {
        JsonlWriter {
            out,
            buffer: Vec::with_capacity(CHUNK + 1024),
            floats: ryu::Buffer::new(),
            integers: itoa::Buffer::new(),
        }
    }

    /// Write out what is buffered and flush the sink.
    pub fn flush(&mut self) -> io::Result<()> {
        self.out.write_all(&self.buffer)?;
        self.buffer.clear();
        self.out.flush()
    }

    fn number(&mut self, x: f64) {
        if x.is_finite() {
            self.buffer
                .extend_from_slice(self.floats.format_finite(x).as_bytes());
        } else {
            self.buffer.extend_from_slice(b"null");
        }
    }

    fn optional(&mut self, x: Option<f64>) {
        match x {
            Some(x) => self.number(x),
            None => self.buffer.extend_from_slice(b"null"),
        }
    }

    fn state(&mut self, names: &[Name], values: &[f64]) {
        self.buffer.push(b'{');
        for (i, (name, value)) in names.iter().zip(values).enumerate() {
            if i > 0 {
                self.buffer.push(b',');
            }
            self.string(name);
            self.buffer.push(b':');
            self.number(*value);
        }
        self.buffer.push(b'}');
    }

    /// Names come from models as plain identifiers; quotes and backslashes
    /// are escaped all the same.
    fn string(&mut self, s: &str) {
        self.buffer.push(b'"');
        for b in s.bytes() {
            if b == b'"' || b == b'\\' {
                self.buffer.push(b'\\');
            }
            self.buffer.push(b);
        }
        self.buffer.push(b'"');
    }
}

impl<W: Write> Observer for JsonlWriter<W> {
    fn on_event(&mut self, e: &EventRecord) -> io::Result<()> {
        self.buffer.extend_from_slice(b"{\"seq\":");
        self.buffer
            .extend_from_slice(self.integers.format(e.seq).as_bytes());
        self.buffer.extend_from_slice(b",\"t\":");
        self.number(e.t);
        self.buffer.extend_from_slice(b",\"guard\":");
        self.string(e.guard);
        self.buffer.extend_from_slice(b",\"mode_before\":");
        self.string(e.mode_before);
        self.buffer.extend_from_slice(b",\"mode_after\":");
        self.string(e.mode_after);
        self.buffer.extend_from_slice(b",\"energy_before\":");
        self.optional(e.energy_before);
        self.buffer.extend_from_slice(b",\"energy_after\":");
        self.optional(e.energy_after);
        self.buffer.extend_from_slice(b",\"before\":");
        self.state(e.names_before, e.before);
        self.buffer.extend_from_slice(b",\"after\":");
        self.state(e.names_after, e.after);
        for (key, value) in e.labels.iter() {
            self.buffer.push(b',');
            self.string(key);
            self.buffer.push(b':');
            match value {
                Label::Count(n) => self
                    .buffer
                    .extend_from_slice(self.integers.format(n).as_bytes()),
                Label::Number(x) => self.number(x),
            }
        }
        if e.shadow {
            self.buffer.extend_from_slice(b",\"shadow\":true");
        }
        self.buffer.extend_from_slice(b"}\n");
        if self.buffer.len() >= CHUNK {
            self.out.write_all(&self.buffer)?;
            self.buffer.clear();
        }
        Ok(())
    }
}

/// Truncate the file at `path` after its last newline, so that a log cut
/// short by a failed write still parses line by line.
pub fn cut_to_last_line(path: &std::path::Path) -> io::Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    let mut file = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(path)?;
    let metadata = file.metadata()?;
    // Only a regular file has an end to cut back to (not /dev/full, whose
    // reads never end).
    if !metadata.is_file() {
        return Ok(());
    }
    let len = metadata.len();
    // Lines are short: the last newline is within the final 64 KiB.
    let start = len.saturating_sub(1 << 16);
    file.seek(SeekFrom::Start(start))?;
    let mut tail = Vec::new();
    file.read_to_end(&mut tail)?;
    let keep = match tail.iter().rposition(|b| *b == b'\n') {
        Some(i) => start + i as u64 + 1,
        None if start == 0 => 0,
        None => return Ok(()),
    };
    if keep < len {
        file.set_len(keep)
    } else {
        Ok(())
    }
}

/// A file created at its first write or flush, not before: a run refused
/// before it starts leaves no empty log behind, and the log of an earlier
/// run in the same folder untouched.
#[derive(Debug)]
pub struct LazyFile {
    path: std::path::PathBuf,
    file: Option<std::fs::File>,
}

impl LazyFile {
    /// The file at `path`, not yet created.
    pub fn new(path: impl Into<std::path::PathBuf>) -> Self {
        LazyFile {
            path: path.into(),
            file: None,
        }
    }

    fn open(&mut self) -> io::Result<&mut std::fs::File> {
        let file = match self.file.take() {
            Some(file) => file,
            None => std::fs::File::create(&self.path)?,
        };
        Ok(self.file.insert(file))
    }
}

impl Write for LazyFile {
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        self.open()?.write(bytes)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.open()?.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::Labels;

    #[test]
    fn a_lazy_file_is_created_at_its_first_write_or_flush_only() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("events.jsonl");
        std::fs::write(&path, "earlier\n").unwrap();
        drop(LazyFile::new(&path));
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "earlier\n");
        let mut file = LazyFile::new(&path);
        file.write_all(b"new\n").unwrap();
        file.flush().unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new\n");
        let empty = dir.path().join("empty.jsonl");
        LazyFile::new(&empty).flush().unwrap();
        assert_eq!(std::fs::read_to_string(&empty).unwrap(), "");
    }

    #[test]
    fn a_half_written_line_is_cut_off() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("events.jsonl");
        std::fs::write(&path, "{\"seq\":1}\n{\"seq\":2}\n{\"se").unwrap();
        cut_to_last_line(&path).unwrap();
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            "{\"seq\":1}\n{\"seq\":2}\n"
        );
        cut_to_last_line(&path).unwrap();
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            "{\"seq\":1}\n{\"seq\":2}\n"
        );
    }

    #[test]
    fn lines_are_json_with_the_documented_keys() {
        let mut w = JsonlWriter::new(Vec::new());
        let event = EventRecord {
            seq: 12,
            t: 0.1,
            guard: "impact",
            mode_before: "flight",
            mode_after: "flight",
            from: 0,
            to: 0,
            energy_before: Some(0.025),
            energy_after: None,
            names_before: crate::names!["strain", "strain_rate"],
            before: &[0.0, -1e-300],
            names_after: crate::names!["strain", "strain_rate"],
            after: &[0.0, f64::NAN],
            labels: &Labels::NONE
                .with("unit", Label::Count(7))
                .with("rel_velocity", Label::Number(0.5))
                .with("x", Label::Number(-0.25)),
            shadow: false,
        };
        w.on_event(&event).unwrap();
        // Past a horizon, the same event flagged last.
        w.on_event(&EventRecord {
            shadow: true,
            ..event
        })
        .unwrap();
        w.flush().unwrap();
        let text = String::from_utf8(w.out).unwrap();
        let (text, shadow) = text.split_once('\n').unwrap();
        let flagged = shadow.strip_suffix(",\"shadow\":true}\n");
        assert_eq!(flagged, text.strip_suffix('}'), "{shadow}");
        assert!(!text.contains("shadow"));
        let v: serde_json::Value = serde_json::from_str(text).unwrap();
        assert_eq!(v["seq"], 12);
        assert_eq!(v["t"], 0.1);
        assert_eq!(v["guard"], "impact");
        assert_eq!(v["energy_before"], 0.025);
        assert!(v["energy_after"].is_null());
        assert_eq!(v["before"]["strain_rate"], -1e-300);
        assert!(v["after"]["strain_rate"].is_null());
        assert_eq!(v["unit"], 7);
        assert_eq!(v["x"], -0.25);
        assert_eq!(v["rel_velocity"], 0.5);
        // In the order the model gave them, after the state.
        let (unit, speed, x) = (
            text.find("\"unit\"").unwrap(),
            text.find("\"rel_velocity\"").unwrap(),
            text.find("\"x\"").unwrap(),
        );
        assert!(text.find("\"after\"").unwrap() < unit && unit < speed && speed < x);
    }
}
