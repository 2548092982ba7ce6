//! Value parsers for clap that refuse a flag value in tdex's words ("--n = 0 is not allowed:
//! …"), naming the flag and the value as given, for single values and comma-separated lists.

use clap::builder::TypedValueParser;
use clap::error::ErrorKind;
use std::ffi::OsStr;
use std::marker::PhantomData;

/// A whole number of at least `min`, of the flag's type `T` (counts: threads, periods,
/// cells, the sampling factor, ...).
#[derive(Clone)]
pub struct Count<T> {
    min: i64,
    /// What a value is, for a list item that is not one ("a whole number of steps").
    kind: &'static str,
    /// What to give instead of a value below `min`.
    advice: &'static str,
    value: PhantomData<fn() -> T>,
}

/// Whole numbers ≥ `min`; below it (or beyond `T`), "FLAG = V is not allowed: `advice`".
pub fn count<T>(min: i64, kind: &'static str, advice: &'static str) -> Count<T> {
    Count {
        min,
        kind,
        advice,
        value: PhantomData,
    }
}

impl<T: TryFrom<i64> + Clone + Send + Sync + 'static> TypedValueParser for Count<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<T, clap::Error> {
        Flag::of(cmd, arg).read(value, self.kind, self.advice, |n: i64| {
            (n >= self.min).then(|| T::try_from(n).ok()).flatten()
        })
    }
}

/// A finite real number > 0, or ≥ 0 if `zero_allowed`.
#[derive(Clone)]
pub struct Real {
    zero_allowed: bool,
    advice: &'static str,
}

/// Finite reals > 0; others "FLAG = V is not allowed: `advice`".
pub fn positive(advice: &'static str) -> Real {
    Real {
        zero_allowed: false,
        advice,
    }
}

/// Finite reals ≥ 0; others "FLAG = V is not allowed: `advice`".
pub fn non_negative(advice: &'static str) -> Real {
    Real {
        zero_allowed: true,
        advice,
    }
}

impl TypedValueParser for Real {
    type Value = f64;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<f64, clap::Error> {
        Flag::of(cmd, arg).read(value, "a number", self.advice, |v: f64| {
            let signed = v > 0.0 || (self.zero_allowed && v == 0.0);
            (v.is_finite() && signed).then_some(v)
        })
    }
}

/// A memory size such as `512M`, `4G`, `1.5G` or `1048576` (bytes), at least 1 MiB.
#[derive(Clone)]
pub struct Size;

impl TypedValueParser for Size {
    type Value = u64;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<u64, clap::Error> {
        let flag = Flag::of(cmd, arg);
        let text = value.to_string_lossy();
        parse_size(&text).map_err(|e| flag.refuse(format!("{} {text}: {e}", flag.name)))
    }
}

/// A size such as `512M`, `4G`, `1.5G`, `100K` or `1048576` (bytes): K, M, G, T are powers
/// of 1024, an optional `B` or `iB` may follow; at least 1 MiB.
fn parse_size(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let lower = t.to_ascii_lowercase();
    let lower = lower
        .strip_suffix("ib")
        .or_else(|| lower.strip_suffix('b'))
        .unwrap_or(&lower);
    let (number, shift) = match lower.chars().last() {
        Some('k') => (&lower[..lower.len() - 1], 10),
        Some('m') => (&lower[..lower.len() - 1], 20),
        Some('g') => (&lower[..lower.len() - 1], 30),
        Some('t') => (&lower[..lower.len() - 1], 40),
        _ => (lower, 0),
    };
    let allowed =
        "give a size such as 512M, 4G or 1.5G (K, M, G, T: powers of 1024; a bare number is bytes)";
    let value: f64 = number
        .trim()
        .parse()
        .map_err(|_| format!("not a size; {allowed}"))?;
    let bytes = value * (1u64 << shift) as f64;
    if !(bytes.is_finite() && bytes >= (1u64 << 20) as f64 && bytes < u64::MAX as f64) {
        return Err(format!("too small or too large: at least 1M; {allowed}"));
    }
    Ok(bytes as u64)
}

/// The flag a value was given to, for the messages.
struct Flag<'a> {
    cmd: &'a clap::Command,
    /// `--name` as typed.
    name: String,
    /// A comma-separated list: the value is one of its items.
    list: bool,
}

impl<'a> Flag<'a> {
    fn of(cmd: &'a clap::Command, arg: Option<&clap::Arg>) -> Self {
        let name = arg
            .and_then(|a| a.get_long())
            .map_or_else(|| "the value".to_string(), |long| format!("--{long}"));
        let list = arg.is_some_and(|a| a.get_value_delimiter().is_some());
        Flag { cmd, name, list }
    }

    /// The value read as a number; empty or unreadable values refused as `kind` wanted.
    fn number<N: std::str::FromStr>(&self, value: &OsStr, kind: &str) -> Result<N, clap::Error> {
        let text = value.to_string_lossy();
        let name = &self.name;
        if text.trim().is_empty() {
            // clap hands an empty list (`--n ""`) to the parser as one empty item, and cannot
            // tell it from an empty item between two commas
            let one = kind.strip_prefix("a ").unwrap_or(kind);
            return Err(self.refuse(if self.list {
                format!(
                    "{name} is empty or has an empty item: give at least one {one}, \
                     comma-separated"
                )
            } else {
                format!("{name} is empty: give {kind}")
            }));
        }
        text.trim().parse().map_err(|_| {
            self.refuse(if self.list {
                format!("{name}: {text:?} is not {kind} (give a comma-separated list)")
            } else {
                format!("{name} = {text:?} is not {kind}")
            })
        })
    }

    /// The value read as a number `N` and kept as `accept` gives it; a number it refuses is
    /// "FLAG = V is not allowed: `advice`".
    fn read<N: std::str::FromStr + std::fmt::Display + Copy, T>(
        &self,
        value: &OsStr,
        kind: &str,
        advice: &str,
        accept: impl FnOnce(N) -> Option<T>,
    ) -> Result<T, clap::Error> {
        let n: N = self.number(value, kind)?;
        accept(n)
            .ok_or_else(|| self.refuse(format!("{} = {n} is not allowed: {advice}", self.name)))
    }

    /// clap's error for an invalid value (exit code 2), in our words.
    fn refuse(&self, message: String) -> clap::Error {
        clap::Error::raw(ErrorKind::ValueValidation, message + "\n").with_cmd(self.cmd)
    }
}

#[cfg(test)]
mod tests {
    use super::parse_size;

    #[test]
    fn sizes_in_powers_of_1024() {
        assert_eq!(parse_size("512M"), Ok(512 << 20));
        assert_eq!(parse_size("4G"), Ok(4 << 30));
        assert_eq!(parse_size("1.5GiB"), Ok(3 << 29));
        assert_eq!(parse_size("1048576"), Ok(1 << 20));
        assert!(parse_size("100K").is_err(), "below 1 MiB");
        assert!(parse_size("lots").is_err());
    }
}
