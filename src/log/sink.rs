//! Whole lines out: [`LineSink`] collects log lines and writes them when told; when a
//! write fails part-way (a full disk), it cuts the output back to the last whole line,
//! so a log never ends in half a line.

use std::fs::File;
use std::io::{self, Seek, SeekFrom, Write};

/// Where a [`LineSink`] writes: a writer that can be cut back to a length.
pub trait Target: Write {
    /// Cuts the output back to `len` bytes. Streams cannot take bytes back and do nothing.
    fn cut(&mut self, len: u64) -> io::Result<()>;
}

impl Target for File {
    fn cut(&mut self, len: u64) -> io::Result<()> {
        self.set_len(len)?;
        self.seek(SeekFrom::Start(len)).map(|_| ())
    }
}

impl Target for io::Stdout {
    fn cut(&mut self, _len: u64) -> io::Result<()> {
        Ok(())
    }
}

impl<T: Target + ?Sized> Target for Box<T> {
    fn cut(&mut self, len: u64) -> io::Result<()> {
        (**self).cut(len)
    }
}

/// Buffers whole lines and writes them to a [`Target`] on [`LineSink::flush`].
pub struct LineSink<T: Target> {
    out: T,
    buf: Vec<u8>,
    /// Bytes of whole lines in the output (its length before we wrote, for appends).
    kept: u64,
    /// Lines this sink wrote out.
    lines: u64,
}

impl<T: Target> LineSink<T> {
    /// A sink writing to `out`, which already holds `len` bytes (0 unless appending).
    pub fn new(out: T, len: u64) -> LineSink<T> {
        LineSink {
            out,
            buf: Vec::with_capacity(1 << 16),
            kept: len,
            lines: 0,
        }
    }
    /// The buffer to append whole lines (each ending in `\n`) to.
    pub fn buffer(&mut self) -> &mut Vec<u8> {
        &mut self.buf
    }
    /// True when lines are waiting to be written.
    pub fn pending(&self) -> bool {
        !self.buf.is_empty()
    }
    /// Lines written out so far.
    pub fn lines(&self) -> u64 {
        self.lines
    }
    /// Writes the buffered lines. On failure the output keeps only the whole lines that
    /// were written (a partial last line is cut off), those lines leave the buffer, and the
    /// error is returned.
    pub fn flush(&mut self) -> io::Result<()> {
        let mut done = 0;
        let failed = loop {
            if done == self.buf.len() {
                break None;
            }
            match self.out.write(&self.buf[done..]) {
                Ok(0) => break Some(io::Error::from(io::ErrorKind::WriteZero)),
                Ok(n) => done += n,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => break Some(e),
            }
        };
        let whole = match failed {
            None => done,
            Some(_) => self.buf[..done].iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1),
        };
        self.lines += self.buf[..whole].iter().filter(|&&b| b == b'\n').count() as u64;
        self.kept += whole as u64;
        self.buf.drain(..whole);
        match failed {
            None => self.out.flush(),
            Some(e) => {
                if done > whole {
                    self.out.cut(self.kept)?;
                }
                Err(e)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A disk with room for `room` more bytes: a write past it is short, then fails ENOSPC.
    struct SmallDisk {
        data: Vec<u8>,
        room: usize,
    }

    impl Write for SmallDisk {
        fn write(&mut self, b: &[u8]) -> io::Result<usize> {
            if self.room == 0 {
                return Err(io::Error::from_raw_os_error(libc::ENOSPC));
            }
            let n = b.len().min(self.room);
            self.data.extend_from_slice(&b[..n]);
            self.room -= n;
            Ok(n)
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    impl Target for SmallDisk {
        fn cut(&mut self, len: u64) -> io::Result<()> {
            self.data.truncate(len as usize);
            Ok(())
        }
    }

    #[test]
    fn a_full_disk_leaves_only_whole_lines() {
        let old = b"(1.000000) can0 123#01\n".to_vec();
        let disk = SmallDisk {
            room: 30,
            data: old.clone(),
        };
        let mut sink = LineSink::new(disk, old.len() as u64);
        sink.buffer()
            .extend_from_slice(b"(2.000000) can0 123#02\n(3.000000) can0 123#03\n");
        let e = sink.flush().unwrap_err();
        assert_eq!(e.raw_os_error(), Some(libc::ENOSPC));
        assert_eq!(sink.lines(), 1);
        assert_eq!(sink.out.data, b"(1.000000) can0 123#01\n(2.000000) can0 123#02\n");
        // The line that did not fit is still buffered; once there is room it goes out whole.
        sink.out.room = 100;
        sink.flush().unwrap();
        assert_eq!(sink.lines(), 2);
        assert!(
            sink.out
                .data
                .ends_with(b"(2.000000) can0 123#02\n(3.000000) can0 123#03\n")
        );
        assert!(!sink.pending());
    }

    #[test]
    fn a_disk_full_before_the_first_line_keeps_nothing() {
        let mut sink = LineSink::new(
            SmallDisk {
                room: 5,
                data: Vec::new(),
            },
            0,
        );
        sink.buffer().extend_from_slice(b"(2.000000) can0 123#02\n");
        assert!(sink.flush().is_err());
        assert_eq!((sink.lines(), sink.out.data.len()), (0, 0));
    }
}
