//! A word when an event log grows large (the command line's, and Python's
//! `log=`): a run to t = 1e7 with its log once wrote 955 MB and said
//! nothing. The log is written as the run goes (an interrupted run keeps
//! what it did), so it is not refused; the user is told once it passes 100
//! MB, and again at each tenfold, that it grows and how to do without it.

use std::io::{self, Write};

/// The first size said, in bytes; then each ten times the last.
pub const FIRST_NOTICE: u64 = 100_000_000;

/// `inner` with the bytes written counted, `say` told when they pass each
/// notice.
pub struct LogSize<W, S: FnMut(String)> {
    inner: W,
    written: u64,
    next_notice: u64,
    say: S,
}

impl<W: Write, S: FnMut(String)> LogSize<W, S> {
    /// Count what goes to `inner`, the first notice at `first` bytes.
    pub fn new(inner: W, first: u64, say: S) -> Self {
        LogSize {
            inner,
            written: 0,
            next_notice: first,
            say,
        }
    }
}

impl<W: Write, S: FnMut(String)> Write for LogSize<W, S> {
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        let n = self.inner.write(bytes)?;
        self.written += n as u64;
        if self.written >= self.next_notice {
            (self.say)(format!(
                "the event log has passed {} MB and grows as the run goes (--no-events, or \
                 no log= from Python, runs without it; `flicker events` filters and \
                 summarises it)",
                self.next_notice / 1_000_000
            ));
            while self.next_notice <= self.written {
                self.next_notice = self.next_notice.saturating_mul(10);
            }
        }
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn it_speaks_once_at_each_tenfold() {
        let mut said = Vec::new();
        {
            let mut log = LogSize::new(io::sink(), 1_000_000, |s| said.push(s));
            for _ in 0..25 {
                log.write_all(&[b'x'; 500_000]).unwrap();
            }
        }
        // 12.5 MB: past 1 MB and 10 MB, not yet 100 MB.
        assert_eq!(said.len(), 2, "{said:?}");
        assert!(said[0].contains("passed 1 MB") && said[0].contains("--no-events"));
        assert!(said[1].contains("passed 10 MB"));
    }
}
