//! The Khepera II serial protocol (ASCII), as a pure codec.
//!
//! A command is one upper-case letter, its arguments separated by commas,
//! ended by a line feed (`D,5,-5\n`). The robot answers with the same letter
//! in lower case and its values (`d`, `n,12,30,...`), ended by `\r\n`. The
//! gripper turret is reached through `T,1,...` (turret 1), answered by
//! `t,1,...`. An unknown command is answered by `z,...`. See `docs/robot.md`
//! for the commands, their units and the timing.
//!
//! Nothing here does I/O: [`Request::encode`] and [`parse_reply`] are what the
//! host sends and reads, [`Request::parse`] and [`Reply::encode`] what a robot
//! (the emulator) reads and sends, and [`LineBuffer`] cuts a byte stream into
//! lines. Every malformed input is an error, never a panic.

use std::fmt;

/// Distance a wheel moves per encoder pulse, mm (Khepera II).
pub const MM_PER_PULSE: f32 = 0.08;
/// Wheel speed of one speed unit (one pulse per 10 ms), mm/s.
pub const MM_S_PER_UNIT: f32 = 8.0;
/// Largest speed the protocol accepts, in units (about 1 m/s).
pub const MAX_SPEED_UNITS: i32 = 127;
/// Largest IR or ambient reading (10-bit converter).
pub const READING_MAX: u16 = 1023;
/// Longest line either side accepts, bytes (without its end of line).
pub const MAX_LINE: usize = 120;
/// Arm position of the gripper turret for "up" (`T,1,E,pos`, 0..255; to be
/// checked on each turret).
pub const ARM_UP: u8 = 180;
/// Arm position for "down".
pub const ARM_DOWN: u8 = 249;

/// A command the host sends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Request {
    /// `B`: software version.
    Version,
    /// `D,l,r`: wheel speeds, in units of [`MM_S_PER_UNIT`].
    SetSpeed([i32; 2]),
    /// `G,l,r`: set the position counters, in pulses.
    SetPosition([i32; 2]),
    /// `H`: read the position counters.
    ReadPosition,
    /// `N`: read the 8 proximity sensors.
    ReadProximity,
    /// `O`: read the 8 ambient light sensors.
    ReadAmbient,
    /// `T,1,D,s`: gripper claw, 1 closed, 0 open.
    Claw(bool),
    /// `T,1,E,p`: gripper arm position 0..255.
    Arm(u8),
    /// `T,1,G`: the optical barrier between the claw's fingers.
    ReadBarrier,
}

/// A robot's answer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Reply {
    /// `b,...`: the version text.
    Version(String),
    /// The acknowledgement of a command that sets something (`d`, `g`,
    /// `t,1,d`, `t,1,e`).
    Done,
    /// `h,l,r`: position counters, pulses.
    Position([i32; 2]),
    /// `n,...`: proximity readings 0..1023, K-Team order (left 90 first).
    Proximity([u16; 8]),
    /// `o,...`: ambient readings 0..1023.
    Ambient([u16; 8]),
    /// `t,1,g,v`: the barrier's reading (0 = nothing between the fingers).
    Barrier(u16),
}

/// A line that is not what the protocol allows.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ProtocolError {
    #[error("empty line")]
    Empty,
    #[error("`{line}` holds byte 0x{byte:02x}, which is not printable ASCII")]
    NotAscii { line: String, byte: u8 },
    #[error("a line longer than {MAX_LINE} bytes")]
    TooLong,
    #[error("`{line}` does not answer `{command}` (an answer starts with `{expected}`)")]
    WrongReply { line: String, command: String, expected: String },
    #[error("`{line}` has {found} values where `{command}` is answered by {expected}")]
    Count { line: String, command: String, expected: usize, found: usize },
    #[error("`{line}`: value {index} (`{text}`) is not an integer in {lo}..={hi}")]
    BadValue { line: String, index: usize, text: String, lo: i64, hi: i64 },
    #[error("the robot refused the command: `{0}`")]
    Refused(String),
    #[error("unknown command `{0}`")]
    UnknownCommand(String),
}

/// A line shown in a message: printable, at most 40 characters.
fn shown(line: &[u8]) -> String {
    let s: String = line.escape_ascii().to_string();
    if s.len() > 40 {
        let cut = s.char_indices().nth(40).map_or(s.len(), |(i, _)| i);
        format!("{}...", &s[..cut])
    } else {
        s
    }
}

/// Checks that `line` is non-empty printable ASCII of at most [`MAX_LINE`] bytes.
fn check_line(line: &[u8]) -> Result<&str, ProtocolError> {
    if line.is_empty() {
        return Err(ProtocolError::Empty);
    }
    if line.len() > MAX_LINE {
        return Err(ProtocolError::TooLong);
    }
    if let Some(&byte) = line.iter().find(|b| !(0x20..0x7f).contains(*b)) {
        return Err(ProtocolError::NotAscii { line: shown(line), byte });
    }
    // Printable ASCII is UTF-8.
    std::str::from_utf8(line).map_err(|_| ProtocolError::NotAscii { line: shown(line), byte: 0 })
}

fn int(line: &str, index: usize, text: &str, lo: i64, hi: i64) -> Result<i64, ProtocolError> {
    let t = text.trim();
    match t.parse::<i64>() {
        Ok(v) if (lo..=hi).contains(&v) => Ok(v),
        _ => Err(ProtocolError::BadValue {
            line: shown(line.as_bytes()),
            index,
            text: shown(t.as_bytes()),
            lo,
            hi,
        }),
    }
}

impl Request {
    /// The command line, with its line feed.
    pub fn encode(&self) -> String {
        match *self {
            Request::Version => "B\n".into(),
            Request::SetSpeed([l, r]) => format!("D,{l},{r}\n"),
            Request::SetPosition([l, r]) => format!("G,{l},{r}\n"),
            Request::ReadPosition => "H\n".into(),
            Request::ReadProximity => "N\n".into(),
            Request::ReadAmbient => "O\n".into(),
            Request::Claw(closed) => format!("T,1,D,{}\n", u8::from(closed)),
            Request::Arm(p) => format!("T,1,E,{p}\n"),
            Request::ReadBarrier => "T,1,G\n".into(),
        }
    }

    /// The prefix of the answer (`d`, `t,1,g`).
    pub fn answer_prefix(&self) -> &'static str {
        match self {
            Request::Version => "b",
            Request::SetSpeed(_) => "d",
            Request::SetPosition(_) => "g",
            Request::ReadPosition => "h",
            Request::ReadProximity => "n",
            Request::ReadAmbient => "o",
            Request::Claw(_) => "t,1,d",
            Request::Arm(_) => "t,1,e",
            Request::ReadBarrier => "t,1,g",
        }
    }

    /// Reads a command line (without its end of line), as a robot does.
    pub fn parse(line: &[u8]) -> Result<Request, ProtocolError> {
        let text = check_line(line)?;
        let fields: Vec<&str> = text.split(',').map(str::trim).collect();
        let unknown = || ProtocolError::UnknownCommand(shown(line));
        let count = |n: usize| {
            if fields.len() == n {
                Ok(())
            } else {
                Err(ProtocolError::Count {
                    line: shown(line),
                    command: fields[0].to_string(),
                    expected: n - 1,
                    found: fields.len() - 1,
                })
            }
        };
        let pair = |lo: i64, hi: i64| -> Result<[i32; 2], ProtocolError> {
            count(3)?;
            Ok([int(text, 1, fields[1], lo, hi)? as i32, int(text, 2, fields[2], lo, hi)? as i32])
        };
        let speed = i64::from(MAX_SPEED_UNITS);
        match fields[0] {
            "B" => count(1).map(|_| Request::Version),
            "D" => pair(-speed, speed).map(Request::SetSpeed),
            "G" => pair(i64::from(i32::MIN), i64::from(i32::MAX)).map(Request::SetPosition),
            "H" => count(1).map(|_| Request::ReadPosition),
            "N" => count(1).map(|_| Request::ReadProximity),
            "O" => count(1).map(|_| Request::ReadAmbient),
            "T" if fields.len() >= 3 && fields[1] == "1" => match fields[2] {
                "D" => {
                    count(4)?;
                    Ok(Request::Claw(int(text, 3, fields[3], 0, 1)? == 1))
                }
                "E" => {
                    count(4)?;
                    Ok(Request::Arm(int(text, 3, fields[3], 0, 255)? as u8))
                }
                "G" => count(3).map(|_| Request::ReadBarrier),
                _ => Err(unknown()),
            },
            _ => Err(unknown()),
        }
    }
}

impl fmt::Display for Request {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.encode().trim_end())
    }
}

impl Reply {
    /// The answer line to `request`, with its `\r\n`.
    pub fn encode(&self, request: &Request) -> String {
        let p = request.answer_prefix();
        let list = |v: &[u16; 8]| v.iter().map(u16::to_string).collect::<Vec<_>>().join(",");
        match self {
            Reply::Version(v) => format!("b,{v}\r\n"),
            Reply::Done => format!("{p}\r\n"),
            Reply::Position([l, r]) => format!("h,{l},{r}\r\n"),
            Reply::Proximity(v) => format!("n,{}\r\n", list(v)),
            Reply::Ambient(v) => format!("o,{}\r\n", list(v)),
            Reply::Barrier(v) => format!("t,1,g,{v}\r\n"),
        }
    }
}

/// Reads the robot's answer `line` (without its end of line) to `request`.
pub fn parse_reply(request: &Request, line: &[u8]) -> Result<Reply, ProtocolError> {
    let text = check_line(line)?;
    if let Some(rest) = text.strip_prefix("z,").or(if text == "z" { Some("") } else { None }) {
        return Err(ProtocolError::Refused(shown(rest.as_bytes())));
    }
    let prefix = request.answer_prefix();
    let wrong = || ProtocolError::WrongReply {
        line: shown(line),
        command: request.to_string(),
        expected: prefix.to_string(),
    };
    let rest = match text.strip_prefix(prefix) {
        Some("") => "",
        Some(r) => r.strip_prefix(',').ok_or_else(wrong)?,
        None => return Err(wrong()),
    };
    let values: Vec<&str> = if rest.is_empty() { Vec::new() } else { rest.split(',').collect() };
    let count = |n: usize| {
        if values.len() == n {
            Ok(())
        } else {
            Err(ProtocolError::Count {
                line: shown(line),
                command: request.to_string(),
                expected: n,
                found: values.len(),
            })
        }
    };
    let readings = || -> Result<[u16; 8], ProtocolError> {
        count(8)?;
        let mut out = [0u16; 8];
        for (k, v) in values.iter().enumerate() {
            out[k] = int(text, k + 1, v, 0, i64::from(READING_MAX))? as u16;
        }
        Ok(out)
    };
    match request {
        Request::Version => Ok(Reply::Version(rest.to_string())),
        Request::SetSpeed(_) | Request::SetPosition(_) | Request::Claw(_) | Request::Arm(_) => {
            count(0).map(|_| Reply::Done)
        }
        Request::ReadPosition => {
            count(2)?;
            let (lo, hi) = (i64::from(i32::MIN), i64::from(i32::MAX));
            Ok(Reply::Position([
                int(text, 1, values[0], lo, hi)? as i32,
                int(text, 2, values[1], lo, hi)? as i32,
            ]))
        }
        Request::ReadProximity => readings().map(Reply::Proximity),
        Request::ReadAmbient => readings().map(Reply::Ambient),
        Request::ReadBarrier => {
            count(1)?;
            Ok(Reply::Barrier(int(text, 1, values[0], 0, 255)? as u16))
        }
    }
}

/// Cuts a byte stream into lines: bytes go in as they arrive, complete lines
/// (without `\r\n` or `\n`) come out. A line longer than [`MAX_LINE`] is an
/// error (and its bytes up to the next line feed are dropped).
#[derive(Clone, Debug, Default)]
pub struct LineBuffer {
    buf: Vec<u8>,
    overflow: bool,
}

impl LineBuffer {
    pub fn new() -> LineBuffer {
        LineBuffer::default()
    }

    /// Appends received bytes.
    pub fn push(&mut self, bytes: &[u8]) {
        self.buf.extend_from_slice(bytes);
    }

    /// The next complete line, if one has arrived.
    pub fn next_line(&mut self) -> Option<Result<Vec<u8>, ProtocolError>> {
        loop {
            let Some(end) = self.buf.iter().position(|&b| b == b'\n') else {
                if self.buf.len() > MAX_LINE + 1 {
                    self.buf.clear();
                    self.overflow = true;
                    return Some(Err(ProtocolError::TooLong));
                }
                return None;
            };
            let mut line: Vec<u8> = self.buf.drain(..=end).collect();
            line.pop();
            if line.last() == Some(&b'\r') {
                line.pop();
            }
            if std::mem::take(&mut self.overflow) {
                // The tail of a line already reported as too long.
                continue;
            }
            if line.len() > MAX_LINE {
                return Some(Err(ProtocolError::TooLong));
            }
            return Some(Ok(line));
        }
    }

    /// Drops everything received so far (stale answers before a new command).
    pub fn clear(&mut self) {
        self.buf.clear();
        self.overflow = false;
    }
}

/// Speed units for a wheel command (-1..1 of `v_max` mm/s), rounded to the
/// nearest unit and clamped to the protocol's range.
pub fn speed_units(command: f32, v_max: f32) -> i32 {
    let u = command * v_max / MM_S_PER_UNIT;
    if u.is_finite() {
        (u.round() as i32).clamp(-MAX_SPEED_UNITS, MAX_SPEED_UNITS)
    } else {
        0
    }
}

/// The wheel command (-1..1 of `v_max`) of a speed in units.
pub fn speed_command(units: i32, v_max: f32) -> f32 {
    if v_max > 0.0 {
        units as f32 * MM_S_PER_UNIT / v_max
    } else {
        0.0
    }
}

/// A reading 0..1023 as a percept value 0..1.
pub fn reading_value(reading: u16) -> f32 {
    f32::from(reading.min(READING_MAX)) / f32::from(READING_MAX)
}

/// A percept value 0..1 as the 10-bit reading a Khepera reports (rounded).
pub fn value_reading(value: f32) -> u16 {
    if value.is_finite() {
        (value.clamp(0.0, 1.0) * f32::from(READING_MAX)).round() as u16
    } else {
        0
    }
}
