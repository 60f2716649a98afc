//! ROS 2 messages read from a bag by their own definitions: the `ros2msg` schema an MCAP channel carries, parsed, and CDR bytes decoded against it into a JSON value.

use std::collections::HashMap;

use serde_json::{Map, Value};

/// The separator between a schema's message definitions.
const SEPARATOR: &str =
    "================================================================================";

/// Deepest nesting of messages decoded: far more than any real message has.
const MAX_DEPTH: usize = 32;

/// Most elements one sequence may claim: a corrupt count cannot make a decoder loop on.
const MAX_SEQUENCE: usize = 1 << 24;

/// Values a message may decode beyond one per byte of its body (empty messages cost none).
const SPARE_VALUES: usize = 1024;

/// A primitive's kind and size in bytes.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Prim {
    Bool,
    I(usize),
    U(usize),
    F(usize),
}

#[derive(Debug, Clone, PartialEq)]
enum Kind {
    Prim(Prim),
    String,
    Msg(String),
}

#[derive(Debug, Clone, PartialEq)]
enum Count {
    One,
    Fixed(usize),
    Sequence,
}

#[derive(Debug, Clone, PartialEq)]
struct Field {
    name: String,
    kind: Kind,
    count: Count,
}

/// A message definition with the definitions it uses, by full name (`pkg/Type`).
#[derive(Debug, Clone, PartialEq)]
pub struct Schema {
    root: String,
    types: HashMap<String, Vec<Field>>,
}

/// `pkg/msg/Type` and `pkg/Type` as `pkg/Type`; a bare `Type` in package `pkg` likewise;
/// `Header` is `std_msgs/Header`.
fn full_name(ty: &str, package: &str) -> String {
    let parts: Vec<&str> = ty.split('/').collect();
    match parts.as_slice() {
        [p, "msg", t] | [p, t] => format!("{p}/{t}"),
        ["Header"] => "std_msgs/Header".to_owned(),
        [t] => format!("{package}/{t}"),
        _ => ty.to_owned(),
    }
}

fn prim(name: &str) -> Option<Kind> {
    let p = match name {
        "bool" => Prim::Bool,
        "byte" | "char" | "uint8" => Prim::U(1),
        "int8" => Prim::I(1),
        "int16" => Prim::I(2),
        "uint16" => Prim::U(2),
        "int32" => Prim::I(4),
        "uint32" => Prim::U(4),
        "int64" => Prim::I(8),
        "uint64" => Prim::U(8),
        "float32" => Prim::F(4),
        "float64" => Prim::F(8),
        _ if name == "string" || name.starts_with("string<=") => return Some(Kind::String),
        _ => return None,
    };
    Some(Kind::Prim(p))
}

/// One definition line as a field; `None` for blanks, comments and constants.
fn field(line: &str, package: &str) -> Result<Option<Field>, DefinitionError> {
    let line = line.split('#').next().unwrap_or("").trim();
    let mut words = line.split_whitespace();
    let (Some(ty), Some(name)) = (words.next(), words.next()) else {
        return Ok(None);
    };
    if name.contains('=') || words.next().is_some_and(|w| w.starts_with('=')) {
        return Ok(None);
    }
    let (base, count) = match ty.split_once('[') {
        None => (ty, Count::One),
        Some((base, rest)) => {
            let inner = rest.trim_end_matches(']');
            let count = if inner.is_empty() || inner.starts_with("<=") {
                Count::Sequence
            } else {
                Count::Fixed(inner.parse().map_err(|_| DefinitionError::ArraySize {
                    line: line.to_owned(),
                })?)
            };
            (base, count)
        }
    };
    if base == "wstring" || base.starts_with("wstring<=") {
        return Err(DefinitionError::WideString {
            line: line.to_owned(),
        });
    }
    let kind = prim(base).unwrap_or_else(|| Kind::Msg(full_name(base, package)));
    Ok(Some(Field {
        name: name.to_owned(),
        kind,
        count,
    }))
}

/// Why a ROS 2 message definition or a message in it could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CdrError {
    /// The definition text (`ros2msg`) is not one this reader understands.
    #[error(transparent)]
    Definition(#[from] DefinitionError),
    /// A message's bytes do not match its definition (short, nested too deeply, not
    /// little-endian).
    #[error(transparent)]
    Message(#[from] MessageError),
}

/// Why a `ros2msg` definition text could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DefinitionError {
    #[error("array size in {line:?}")]
    ArraySize { line: String },
    #[error("{line:?}: wide strings are not read")]
    WideString { line: String },
    #[error("field {field} is of type {ty}, not defined")]
    Undefined { field: String, ty: String },
}

/// Why a message's CDR bytes do not match its definition.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum MessageError {
    #[error("shorter than the CDR header")]
    NoHeader,
    #[error("not little-endian CDR")]
    NotLittleEndian,
    #[error("nested too deeply")]
    TooDeep,
    #[error("type {0} not defined")]
    Undefined(String),
    #[error("{field}: {count} elements in {left} bytes")]
    Sequence {
        field: String,
        count: usize,
        left: usize,
    },
    #[error("its schema asks for more values than its {0} bytes hold")]
    TooManyValues(usize),
    #[error("ends {wanted} bytes early at {at}")]
    Short { wanted: usize, at: usize },
}

impl Schema {
    /// The schema of a channel whose messages are `name` (`pkg/msg/Type`).
    pub fn parse(name: &str, text: &str) -> Result<Self, CdrError> {
        Ok(Self::parse_text(name, text)?)
    }

    fn parse_text(name: &str, text: &str) -> Result<Self, DefinitionError> {
        let root = full_name(name, "");
        let mut types = HashMap::new();
        let mut current = root.clone();
        let mut fields = Vec::new();
        for line in text.lines() {
            if line.trim() == SEPARATOR {
                types.insert(std::mem::take(&mut current), std::mem::take(&mut fields));
                continue;
            }
            if let Some(t) = line.strip_prefix("MSG: ") {
                current = full_name(t.trim(), "");
                continue;
            }
            let package = current.split('/').next().unwrap_or("").to_owned();
            if let Some(f) = field(line, &package)? {
                fields.push(f);
            }
        }
        types.insert(current, fields);
        let schema = Self { root, types };
        schema.check()?;
        Ok(schema)
    }

    /// Every message type a field names is defined.
    fn check(&self) -> Result<(), DefinitionError> {
        for fields in self.types.values() {
            for f in fields {
                if let Kind::Msg(t) = &f.kind
                    && !self.types.contains_key(t)
                {
                    return Err(DefinitionError::Undefined {
                        field: f.name.clone(),
                        ty: t.clone(),
                    });
                }
            }
        }
        Ok(())
    }

    /// A message's CDR bytes (with their encapsulation header) as JSON.
    pub fn decode(&self, bytes: &[u8]) -> Result<Value, CdrError> {
        Ok(self.decode_bytes(bytes)?)
    }

    fn decode_bytes(&self, bytes: &[u8]) -> Result<Value, MessageError> {
        let body = bytes.get(4..).ok_or(MessageError::NoHeader)?;
        if bytes[1] != 0x01 {
            return Err(MessageError::NotLittleEndian);
        }
        // Every value costs at least one byte save empty messages: a schema declaring a
        // billion of them must not build a billion values from no bytes.
        let mut r = Reader {
            body,
            at: 0,
            values_left: body.len() + SPARE_VALUES,
        };
        self.message(&self.root, &mut r, 0)
    }

    fn message(&self, ty: &str, r: &mut Reader<'_>, depth: usize) -> Result<Value, MessageError> {
        if depth > MAX_DEPTH {
            return Err(MessageError::TooDeep);
        }
        let fields = self
            .types
            .get(ty)
            .ok_or_else(|| MessageError::Undefined(ty.to_owned()))?;
        let mut out = Map::new();
        for f in fields {
            let v = match f.count {
                Count::One => self.value(&f.kind, r, depth)?,
                Count::Fixed(n) => self.values(&f.kind, n, r, depth)?,
                Count::Sequence => {
                    let n = r.u32()? as usize;
                    if n > MAX_SEQUENCE || n > r.left() {
                        return Err(MessageError::Sequence {
                            field: f.name.clone(),
                            count: n,
                            left: r.left(),
                        });
                    }
                    self.values(&f.kind, n, r, depth)?
                }
            };
            out.insert(f.name.clone(), v);
        }
        Ok(Value::Object(out))
    }

    fn values(
        &self,
        k: &Kind,
        n: usize,
        r: &mut Reader<'_>,
        d: usize,
    ) -> Result<Value, MessageError> {
        let items: Result<Vec<Value>, MessageError> = (0..n).map(|_| self.value(k, r, d)).collect();
        Ok(Value::Array(items?))
    }

    fn value(&self, kind: &Kind, r: &mut Reader<'_>, depth: usize) -> Result<Value, MessageError> {
        r.values_left = r
            .values_left
            .checked_sub(1)
            .ok_or(MessageError::TooManyValues(r.body.len()))?;
        match kind {
            Kind::Prim(p) => r.prim(*p),
            Kind::String => r.string(),
            Kind::Msg(t) => self.message(t, r, depth + 1),
        }
    }
}

/// A cursor over a message's body; primitives are aligned to their size from its start.
struct Reader<'a> {
    body: &'a [u8],
    at: usize,
    /// Values still to be decoded before the message is refused.
    values_left: usize,
}

impl Reader<'_> {
    fn left(&self) -> usize {
        self.body.len().saturating_sub(self.at)
    }

    fn take(&mut self, n: usize) -> Result<&[u8], MessageError> {
        let end = self.at.checked_add(n).filter(|e| *e <= self.body.len());
        let end = end.ok_or(MessageError::Short {
            wanted: n,
            at: self.at,
        })?;
        let s = &self.body[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn aligned(&mut self, n: usize) -> Result<&[u8], MessageError> {
        self.at = self.at.div_ceil(n) * n;
        self.take(n)
    }

    fn u32(&mut self) -> Result<u32, MessageError> {
        let b = self.aligned(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn prim(&mut self, p: Prim) -> Result<Value, MessageError> {
        let n = match p {
            Prim::Bool => 1,
            Prim::I(n) | Prim::U(n) | Prim::F(n) => n,
        };
        let b = self.aligned(n)?;
        let mut w = [0u8; 8];
        w[..n].copy_from_slice(b);
        let x = match p {
            Prim::Bool => return Ok(Value::Bool(b[0] != 0)),
            Prim::U(_) => u64::from_le_bytes(w) as f64,
            Prim::I(n) => {
                let shift = 64 - 8 * n as u32;
                ((i64::from_le_bytes(w) << shift) >> shift) as f64
            }
            Prim::F(4) => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Prim::F(_) => f64::from_le_bytes(w),
        };
        Ok(serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number))
    }

    fn string(&mut self) -> Result<Value, MessageError> {
        let n = self.u32()? as usize;
        let b = self.take(n)?;
        let text = b.strip_suffix(&[0]).unwrap_or(b);
        Ok(Value::String(String::from_utf8_lossy(text).into_owned()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const STAMPED: &str = "std_msgs/Header header\nfloat64 data # a value\nint16 SMALL=-3\n\
        int16[] small\nstring[2] names\n\
        ================================================================================\n\
        MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n\
        ================================================================================\n\
        MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";

    /// Bytes laid out by hand as CDR: each primitive aligned to its size after the header.
    #[test]
    fn a_message_decodes_by_its_schema() {
        let schema = Schema::parse("pkg/msg/Stamped", STAMPED).expect("schema");
        let mut b = vec![0, 1, 0, 0];
        b.extend(5i32.to_le_bytes()); // sec
        b.extend(250_000_000u32.to_le_bytes()); // nanosec
        b.extend(4u32.to_le_bytes()); // frame_id "map\0"
        b.extend(b"map\0");
        b.extend(1.5f64.to_le_bytes()); // at body offset 16: aligned for 8 bytes
        b.extend(2u32.to_le_bytes()); // small: 2 elements
        b.extend((-7i16).to_le_bytes());
        b.extend(9i16.to_le_bytes());
        for s in ["a\0", "bc\0"] {
            b.extend(u32::try_from(s.len()).expect("short").to_le_bytes());
            b.extend(s.as_bytes());
            while (b.len() - 4) % 4 != 0 {
                b.push(0);
            }
        }
        let v = schema.decode(&b).expect("decodes");
        assert_eq!(v["header"]["stamp"]["sec"], 5.0);
        assert_eq!(v["header"]["frame_id"], "map");
        assert_eq!(v["data"], 1.5);
        assert_eq!(v["small"], serde_json::json!([-7.0, 9.0]));
        assert_eq!(v["names"], serde_json::json!(["a", "bc"]));
        // Cut short, or a sequence claiming more than the bytes hold: an error, not a panic.
        assert!(schema.decode(&b[..20]).is_err());
        let mut huge = b.clone();
        huge[28..32].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(schema.decode(&huge).is_err());
        assert!(Schema::parse("pkg/msg/Bad", "pkg/Missing m\n").is_err());
    }

    /// Values cost bytes: a schema of a billion empty messages (or of a billion zero-size
    /// values) is refused from a few bytes, at once and without building them.
    #[test]
    fn a_schema_cannot_make_values_from_no_bytes() {
        let bomb = "pkg/Empty[1000000000] e\n\
            ================================================================================\n\
            MSG: pkg/Empty\n";
        let schema = Schema::parse("pkg/msg/Bomb", bomb).expect("schema");
        let t0 = std::time::Instant::now();
        let e = schema.decode(&[0, 1, 0, 0]).expect_err("refused");
        assert!(e.to_string().contains("more values than"), "{e}");
        assert!(t0.elapsed().as_secs() < 5);
        // Nested: a thousand of a thousand of a thousand.
        let nested = "pkg/A[1000] a\n\
            ================================================================================\n\
            MSG: pkg/A\npkg/B[1000] b\n\
            ================================================================================\n\
            MSG: pkg/B\npkg/Empty[1000] c\n\
            ================================================================================\n\
            MSG: pkg/Empty\n";
        let schema = Schema::parse("pkg/msg/Nested", nested).expect("schema");
        assert!(schema.decode(&[0, 1, 0, 0, 0, 0, 0, 0]).is_err());
    }
}
