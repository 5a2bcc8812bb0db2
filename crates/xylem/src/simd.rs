//! The SIMD level: which instruction set the hot loops compiled more than once (noise lane
//! kernels, the wood colour blocks, the sparse-noise block search, the wide-BVH traversal) run
//! on. The features of each level are listed once, in `simd_level!`: the same list gives the
//! `#[target_feature]` of every function compiled for the level and the run-time check that
//! lets it run, so the two cannot drift apart. [`Simd::best`] is the one place that decides.
//!
//! `XYLEM_SIMD=scalar|sse2|avx2|avx512` forces a level (for tests and comparisons); a level the
//! CPU lacks is clamped down to the widest it has, with a message, never executed. Every level
//! gives the same values (each kernel's tests compare them), so the level changes speed only.

use std::sync::OnceLock;

/// The instruction sets the multi-compiled kernels run on, in increasing width.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Simd {
    /// One point at a time (every target).
    Scalar,
    /// 4 lanes; part of the x86-64 baseline.
    Sse2,
    /// 8 lanes (with `vpmulld` for the hash multiply).
    Avx2,
    /// 16 lanes (AVX-512 F, BW, DQ, VL).
    Avx512,
}

/// The one list of each level's features. `simd_level!(Avx2 items…)` compiles the items (x86-64
/// only) with `#[target_feature]` enabling exactly them; `simd_level!(Avx2 names)` is the list
/// as `&[&str]`; `simd_level!(Avx2 cpu)` whether the CPU reports all of them. The lists name
/// every feature the attribute enables, implied ones included (`avx512f` implies `avx2`, `fma`
/// and `f16c` in rustc); the SSE/AVX chain below `avx2` is implied by it on every CPU.
macro_rules! simd_level {
    (Avx2 $($rest:tt)*) => { $crate::simd::with_features! { ["avx2"] $($rest)* } };
    (Avx512 $($rest:tt)*) => {
        $crate::simd::with_features! {
            ["avx2", "fma", "f16c", "avx512f", "avx512bw", "avx512dq", "avx512vl"] $($rest)*
        }
    };
}
pub(crate) use simd_level;

/// One function compiled for AVX2 and for AVX-512 (each through [`simd_level!`]): the two
/// trampolines a dispatch site calls share their signature and body, so they are written once.
/// With `where lanes = L` the body names the level's register type as `L` (`__m256`,
/// `__m512`), for the lane-generic kernels of `noise::lanes`.
macro_rules! simd_wide {
    (
        $(#[$meta:meta])*
        unsafe fn $avx2:ident / $avx512:ident $(<$(const $cg:ident: $ct:ty),+>)?
        ($($args:tt)*) $(-> $ret:ty)?
        $(where lanes = $lanes:ident)?
        $body:block
    ) => {
        $crate::simd::simd_level! { Avx2
            $(#[$meta])*
            unsafe fn $avx2 $(<$(const $cg: $ct),+>)? ($($args)*) $(-> $ret)? {
                $(type $lanes = std::arch::x86_64::__m256;)?
                $body
            }
        }
        $crate::simd::simd_level! { Avx512
            $(#[$meta])*
            unsafe fn $avx512 $(<$(const $cg: $ct),+>)? ($($args)*) $(-> $ret)? {
                $(type $lanes = std::arch::x86_64::__m512;)?
                $body
            }
        }
    };
}
pub(crate) use simd_wide;

/// The three uses of a feature list (see [`simd_level!`]).
macro_rules! with_features {
    ([$($f:tt),+] names) => { &[$($f),+] };
    ([$($f:tt),+] cpu) => { true $(&& std::arch::is_x86_feature_detected!($f))+ };
    ([$($f:tt),+]) => {};
    ([$($f:tt),+] $item:item $($rest:item)*) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature($(enable = $f),+)]
        $item
        $crate::simd::with_features! { [$($f),+] $($rest)* }
    };
}
pub(crate) use with_features;

/// An `XYLEM_SIMD` value that names no level.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("XYLEM_SIMD={value} is not one of {levels}")]
pub struct UnknownSimdLevel {
    /// The value given (quoted).
    pub value: String,
    /// The levels' names.
    pub levels: String,
}

impl Simd {
    /// Every level, narrowest first.
    pub const ALL: [Simd; 4] = [Simd::Scalar, Simd::Sse2, Simd::Avx2, Simd::Avx512];

    /// The level the kernels run on: the widest this CPU has ([`Simd::detected`]), or the one
    /// `XYLEM_SIMD` asks for if that is narrower (a wider one is clamped, with a message on
    /// stderr; an unknown name is reported and ignored — the CLI refuses it up front with
    /// [`Simd::from_env`]).
    ///
    /// Cached in a `OnceLock`, the one exception to "no global state": the answer is a pure
    /// function of the CPU and of the process environment at the first call, the same on every
    /// call, and no output depends on it (every level gives the same values). Caching keeps
    /// per-point callers (`Fractal::eval`, the sparse block search) from re-reading the
    /// environment on every point.
    pub fn best() -> Simd {
        static LEVEL: OnceLock<Simd> = OnceLock::new();
        *LEVEL.get_or_init(|| {
            let forced = Simd::from_env().unwrap_or_else(|e| {
                eprintln!("warning: {e}; ignored");
                None
            });
            let (level, note) = Simd::choose(forced, Simd::detected());
            if let Some(note) = note {
                eprintln!("warning: {note}");
            }
            level
        })
    }

    /// The widest level this CPU reports every feature of (Scalar off x86-64).
    pub fn detected() -> Simd {
        Simd::decide(Simd::cpu_has)
    }

    /// The decision itself: the widest level for which `has(level)` holds (Scalar always does).
    pub fn decide(has: impl Fn(Simd) -> bool) -> Simd {
        Simd::ALL
            .into_iter()
            .rev()
            .find(|&s| s == Simd::Scalar || has(s))
            .unwrap_or(Simd::Scalar)
    }

    /// A forced level capped at the `available` one, with a message when it had to be capped.
    pub(crate) fn choose(forced: Option<Simd>, available: Simd) -> (Simd, Option<String>) {
        match forced {
            Some(f) if f > available => (
                available,
                Some(format!(
                    "XYLEM_SIMD={} needs CPU features {:?}, which this CPU does not all have; \
                     using {}",
                    f.name(),
                    f.features(),
                    available.name()
                )),
            ),
            Some(f) => (f, None),
            None => (available, None),
        }
    }

    /// The level named by `XYLEM_SIMD`, if set; an error naming the allowed values if unknown.
    pub fn from_env() -> Result<Option<Simd>, UnknownSimdLevel> {
        let unknown = |value: String| UnknownSimdLevel {
            value,
            levels: Simd::names(),
        };
        match std::env::var("XYLEM_SIMD") {
            Err(std::env::VarError::NotPresent) => Ok(None),
            Err(std::env::VarError::NotUnicode(v)) => Err(unknown(format!("{v:?}"))),
            Ok(v) => Simd::parse(&v)
                .map(Some)
                .ok_or_else(|| unknown(format!("{v:?}"))),
        }
    }

    /// The level of a [`Simd::name`].
    pub fn parse(name: &str) -> Option<Simd> {
        Simd::ALL.into_iter().find(|s| s.name() == name)
    }

    fn names() -> String {
        Simd::ALL.map(Simd::name).join(", ")
    }

    /// Whether this CPU reports every feature of the level (x86-64 runs SSE2 always).
    fn cpu_has(self) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            match self {
                Simd::Scalar | Simd::Sse2 => true,
                Simd::Avx2 => simd_level!(Avx2 cpu),
                Simd::Avx512 => simd_level!(Avx512 cpu),
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            self == Simd::Scalar
        }
    }

    /// The CPU features this level's code is compiled for (and the CPU must report).
    pub fn features(self) -> &'static [&'static str] {
        match self {
            Simd::Scalar | Simd::Sse2 => &[],
            Simd::Avx2 => simd_level!(Avx2 names),
            Simd::Avx512 => simd_level!(Avx512 names),
        }
    }

    /// Its name, as `XYLEM_SIMD` takes it (and for benchmark tables).
    pub fn name(self) -> &'static str {
        match self {
            Simd::Scalar => "scalar",
            Simd::Sse2 => "sse2",
            Simd::Avx2 => "avx2",
            Simd::Avx512 => "avx512",
        }
    }

    /// Points per kernel call.
    pub fn lanes(self) -> usize {
        match self {
            Simd::Scalar => 1,
            Simd::Sse2 => 4,
            Simd::Avx2 => 8,
            Simd::Avx512 => 16,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The decision for a CPU reporting exactly `cpu` (an x86-64 one: SSE2 is baseline).
    fn decide_for(cpu: &[&str]) -> Simd {
        Simd::decide(|s| s.features().iter().all(|f| cpu.contains(f)))
    }

    #[test]
    fn a_level_needs_every_feature_it_is_compiled_for() {
        // Knights Landing: AVX-512 F (and CD, ER, PF) but not BW, DQ, VL — the AVX2 level.
        let knl = ["avx2", "fma", "f16c", "avx512f", "avx512cd"];
        assert_eq!(decide_for(&knl), Simd::Avx2);
        // Skylake-SP and later: all four.
        let skx = [
            "avx2", "fma", "f16c", "avx512f", "avx512bw", "avx512dq", "avx512vl",
        ];
        assert_eq!(decide_for(&skx), Simd::Avx512);
        // Any one of the four missing drops to AVX2.
        for missing in ["avx512f", "avx512bw", "avx512dq", "avx512vl"] {
            let cpu: Vec<&str> = skx.into_iter().filter(|&f| f != missing).collect();
            assert_eq!(decide_for(&cpu), Simd::Avx2, "without {missing}");
        }
        assert_eq!(decide_for(&["avx", "fma"]), Simd::Sse2);
        assert_eq!(Simd::decide(|_| false), Simd::Scalar);
    }

    #[test]
    fn a_forced_level_is_never_wider_than_the_cpu() {
        assert_eq!(Simd::choose(None, Simd::Avx2), (Simd::Avx2, None));
        assert_eq!(
            Simd::choose(Some(Simd::Sse2), Simd::Avx2),
            (Simd::Sse2, None)
        );
        let (level, note) = Simd::choose(Some(Simd::Avx512), Simd::Avx2);
        assert_eq!(level, Simd::Avx2);
        let note = note.expect("clamping says so");
        assert!(
            note.contains("avx512bw") && note.contains("using avx2"),
            "{note}"
        );
        assert!(Simd::best() <= Simd::detected());
    }

    #[test]
    fn names_round_trip() {
        for s in Simd::ALL {
            assert_eq!(Simd::parse(s.name()), Some(s));
        }
        assert_eq!(Simd::parse("avx512f"), None);
        assert_eq!(Simd::parse("AVX2"), None);
    }
}
