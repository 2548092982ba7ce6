//! Which vector instructions the engine's hot loops use: the widest this CPU has, or narrower
//! ones when `TDEX_SIMD` asks (to see a smaller CPU's speed here, or to compare the builds on
//! one machine). Every build computes the same bits, so the choice changes the speed only.

use std::sync::OnceLock;

/// The environment variable that caps the vector instructions.
pub const ENV: &str = "TDEX_SIMD";

/// A set of vector instructions the engine has a build of its hot loops for, narrowest first;
/// serialised as its [`name`](Simd::name).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(into = "&'static str")]
pub enum Simd {
    /// One double at a time (whatever the compiler makes of the baseline x86-64 or other CPU).
    Scalar,
    /// AVX2: the pair law four contacts at a time.
    Avx2,
    /// AVX-512 (F, VL and BW): the pair law eight contacts at a time and the list scan eight
    /// entries at a time.
    Avx512,
}

/// `TDEX_SIMD` holds a value that names no instruction set.
#[derive(Debug, thiserror::Error)]
#[error("{ENV}={value:?} is not an instruction set tdex has a build for: use avx512, avx2 or scalar (a cap: the widest this CPU has is used when it is unset)")]
pub struct SimdError {
    pub value: String,
}

impl Simd {
    /// Every set, narrowest first.
    pub const ALL: [Simd; 3] = [Simd::Scalar, Simd::Avx2, Simd::Avx512];

    /// The widest set this CPU has.
    pub fn detected() -> Simd {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("avx512vl")
                && std::arch::is_x86_feature_detected!("avx512bw")
            {
                return Simd::Avx512;
            }
            if std::arch::is_x86_feature_detected!("avx2") {
                return Simd::Avx2;
            }
        }
        Simd::Scalar
    }

    /// The cap `TDEX_SIMD` asks for, if it is set.
    pub fn requested() -> Result<Option<Simd>, SimdError> {
        match std::env::var(ENV) {
            Err(_) => Ok(None),
            Ok(value) => Simd::cap(&value),
        }
    }

    /// The cap a value of `TDEX_SIMD` names: none for an empty value (as if unset), any
    /// case and surrounding spaces allowed.
    pub fn cap(value: &str) -> Result<Option<Simd>, SimdError> {
        match value.trim().to_ascii_lowercase().as_str() {
            "" => Ok(None),
            "avx512" | "avx-512" => Ok(Some(Simd::Avx512)),
            "avx2" => Ok(Some(Simd::Avx2)),
            "scalar" | "none" => Ok(Some(Simd::Scalar)),
            _ => Err(SimdError {
                value: value.to_string(),
            }),
        }
    }

    /// The set the engine uses: the widest detected, capped by `TDEX_SIMD` (read once; a
    /// value that names no set leaves the widest, and the CLI refuses it before any work).
    pub fn in_use() -> Simd {
        static IN_USE: OnceLock<Simd> = OnceLock::new();
        *IN_USE.get_or_init(|| {
            let cap = Simd::requested().ok().flatten().unwrap_or(Simd::Avx512);
            Simd::detected().min(cap)
        })
    }

    /// Every set this CPU can run, narrowest first (the tests check each against the others).
    pub fn available() -> impl Iterator<Item = Simd> {
        let widest = Simd::detected();
        Simd::ALL.into_iter().filter(move |&s| s <= widest)
    }

    /// Plain words for a user.
    pub fn describe(self) -> &'static str {
        match self {
            Simd::Scalar => "none (one contact at a time)",
            Simd::Avx2 => "AVX2 (four contacts at a time)",
            Simd::Avx512 => "AVX-512 (eight contacts or list entries at a time)",
        }
    }

    /// A few words for after a thread count ("2 threads, AVX2 vectors").
    pub fn vectors(self) -> &'static str {
        match self {
            Simd::Scalar => "no vector instructions",
            Simd::Avx2 => "AVX2 vectors",
            Simd::Avx512 => "AVX-512 vectors",
        }
    }

    /// The set a recording's costs name (its [`name`](Simd::name), exactly), if any.
    pub fn from_name(name: &str) -> Option<Simd> {
        Simd::ALL.into_iter().find(|s| s.name() == name)
    }

    /// The name `TDEX_SIMD` takes.
    pub fn name(self) -> &'static str {
        match self {
            Simd::Scalar => "scalar",
            Simd::Avx2 => "avx2",
            Simd::Avx512 => "avx512",
        }
    }
}

impl From<Simd> for &'static str {
    fn from(simd: Simd) -> Self {
        simd.name()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cap_is_read_in_any_case_and_an_empty_one_is_no_cap() {
        assert_eq!(Simd::cap(" AVX2 ").unwrap(), Some(Simd::Avx2));
        assert_eq!(Simd::cap("avx-512").unwrap(), Some(Simd::Avx512));
        assert_eq!(Simd::cap("Scalar").unwrap(), Some(Simd::Scalar));
        assert_eq!(Simd::cap("").unwrap(), None);
        let refused = Simd::cap("sse4").unwrap_err().to_string();
        assert!(
            refused.contains("TDEX_SIMD=\"sse4\"") && refused.contains("avx512, avx2 or scalar"),
            "{refused}"
        );
    }

    #[test]
    fn every_set_is_found_by_its_name_and_only_by_it() {
        for simd in Simd::ALL {
            assert_eq!(Simd::from_name(simd.name()), Some(simd));
        }
        assert_eq!(Simd::from_name("AVX2"), None);
        assert_eq!(Simd::from_name(""), None);
    }

    #[test]
    fn the_set_in_use_is_one_this_cpu_has() {
        assert!(Simd::in_use() <= Simd::detected());
        assert_eq!(Simd::available().last(), Some(Simd::detected()));
        assert_eq!(Simd::available().next(), Some(Simd::Scalar));
    }
}
