//! Whole records out: [`LineSink`] collects log records (candump lines, pcapng blocks) and
//! writes them when told; when a write fails part-way (a full disk), it cuts the output
//! back to the last whole record, so a log never ends in half a line or half a block.

use std::fs::File;
use std::io::{self, Seek, SeekFrom, Write};

/// Where a [`LineSink`] writes: a writer that can be cut back to a length.
pub trait Target: Write {
    /// Cuts the output back to `len` bytes. Streams cannot take bytes back and do nothing.
    fn cut(&mut self, len: u64) -> io::Result<()>;
    /// Writes `bytes` over the output's first bytes (a BLF header's final totals), then
    /// goes on at the end. Streams cannot and do nothing.
    fn rewrite_start(&mut self, bytes: &[u8]) -> io::Result<()>;
}

impl Target for File {
    fn cut(&mut self, len: u64) -> io::Result<()> {
        self.set_len(len)?;
        self.seek(SeekFrom::Start(len)).map(|_| ())
    }
    fn rewrite_start(&mut self, bytes: &[u8]) -> io::Result<()> {
        use std::os::unix::fs::FileExt;
        self.write_all_at(bytes, 0)
    }
}

impl Target for io::Stdout {
    fn cut(&mut self, _len: u64) -> io::Result<()> {
        Ok(())
    }
    fn rewrite_start(&mut self, _bytes: &[u8]) -> io::Result<()> {
        Ok(())
    }
}

impl<T: Target + ?Sized> Target for Box<T> {
    fn cut(&mut self, len: u64) -> io::Result<()> {
        (**self).cut(len)
    }
    fn rewrite_start(&mut self, bytes: &[u8]) -> io::Result<()> {
        (**self).rewrite_start(bytes)
    }
}

/// Buffers whole lines and writes them to a [`Target`] on [`LineSink::flush`].
pub struct LineSink<T: Target> {
    out: T,
    buf: Vec<u8>,
    /// Bytes of whole lines in the output (its length before we wrote, for appends).
    kept: u64,
    /// Frame records this sink wrote out.
    lines: u64,
    /// Where each record in `buf` ends, and how many frames it holds (a pcapng header none,
    /// a BLF container many).
    ends: std::collections::VecDeque<(usize, u64)>,
}

impl<T: Target> LineSink<T> {
    /// A sink writing to `out`, which already holds `len` bytes (0 unless appending).
    pub fn new(out: T, len: u64) -> LineSink<T> {
        LineSink {
            out,
            buf: Vec::with_capacity(1 << 16),
            kept: len,
            lines: 0,
            ends: std::collections::VecDeque::new(),
        }
    }
    /// The buffer to append a record to; [`LineSink::end_record`] marks its end.
    pub fn buffer(&mut self) -> &mut Vec<u8> {
        &mut self.buf
    }
    /// Marks the end of the record just appended; `frame` when it holds a frame (counted
    /// in [`LineSink::lines`]).
    pub fn end_record(&mut self, frame: bool) {
        self.end_frames(frame as u64);
    }
    /// Marks the end of the record just appended, which holds `frames` frames.
    pub fn end_frames(&mut self, frames: u64) {
        self.ends.push_back((self.buf.len(), frames));
    }
    /// The output, to write over its start (see [`Target::rewrite_start`]).
    pub fn target(&mut self) -> &mut T {
        &mut self.out
    }
    /// True when lines are waiting to be written.
    pub fn pending(&self) -> bool {
        !self.buf.is_empty()
    }
    /// Frame records written out so far.
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
        // The output keeps the records written whole; bytes past the last marked end (none
        // when the caller marks every record) count as one record.
        let mut whole = 0;
        while let Some(&(end, frame)) = self.ends.front() {
            if end > done {
                break;
            }
            whole = end;
            self.lines += frame;
            self.ends.pop_front();
        }
        if failed.is_none() {
            whole = done;
        }
        self.kept += whole as u64;
        self.buf.drain(..whole);
        for (end, _) in self.ends.iter_mut() {
            *end -= whole;
        }
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
        fn rewrite_start(&mut self, bytes: &[u8]) -> io::Result<()> {
            self.data[..bytes.len()].copy_from_slice(bytes);
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
        for line in [&b"(2.000000) can0 123#02\n"[..], b"(3.000000) can0 123#03\n"] {
            sink.buffer().extend_from_slice(line);
            sink.end_record(true);
        }
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
    fn binary_records_are_kept_whole_and_headers_are_not_counted() {
        let mut sink = LineSink::new(
            SmallDisk {
                room: 10,
                data: Vec::new(),
            },
            0,
        );
        sink.buffer().extend_from_slice(&[1; 4]);
        sink.end_record(false);
        sink.buffer().extend_from_slice(&[2; 8]);
        sink.end_record(true);
        assert!(sink.flush().is_err());
        assert_eq!((sink.lines(), sink.out.data.clone()), (0, vec![1; 4]));
        sink.out.room = 100;
        sink.flush().unwrap();
        assert_eq!(sink.lines(), 1);
        assert_eq!(sink.out.data.len(), 12);
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
        sink.end_record(true);
        assert!(sink.flush().is_err());
        assert_eq!((sink.lines(), sink.out.data.len()), (0, 0));
    }
}
