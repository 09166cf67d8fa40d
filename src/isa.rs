//! Which vector instruction set this CPU runs, and the one way into code compiled for it.
//! The kernels that have wide versions (the 16-ray packet queries, the sample pattern's chunk
//! fills) are [`Kernel`]s: [`Cpu::dispatch`] runs one inside a `#[target_feature]` function of
//! the detected set (one per set, with the set's one feature string), handing it the set's
//! [`Token`], and vector code takes that token as its proof that the intrinsics it calls exist
//! on this CPU. So one binary runs on any x86-64 (and elsewhere, on the portable code), and
//! every version computes the same bits. Every vector entry point of the crate (packet queries,
//! pattern fills, the integrator's lane kernels and camera rays) goes through it.

/// A vector instruction set, narrowest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Isa {
    /// Plain code for whatever the build targets (any CPU).
    Portable,
    /// x86-64 with AVX2.
    Avx2,
    /// x86-64 with AVX-512 F, BW, DQ and VL.
    Avx512,
}

impl Isa {
    /// The widest set this CPU runs.
    pub fn detect() -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx512f")
                && std::is_x86_feature_detected!("avx512bw")
                && std::is_x86_feature_detected!("avx512dq")
                && std::is_x86_feature_detected!("avx512vl")
            {
                return Isa::Avx512;
            }
            if std::is_x86_feature_detected!("avx2") {
                return Isa::Avx2;
            }
        }
        Isa::Portable
    }

    /// `self` if this CPU runs it, else the widest set it does run (so any value is safe to
    /// dispatch on).
    #[inline]
    pub fn supported(self) -> Isa {
        self.min(Isa::detect())
    }

    /// Every set this CPU runs, narrowest first (tests compare them).
    pub fn available() -> Vec<Isa> {
        let best = Isa::detect();
        [Isa::Portable, Isa::Avx2, Isa::Avx512]
            .into_iter()
            .filter(|&i| i <= best)
            .collect()
    }
}

/// Proof that this CPU runs an instruction set. A token of a vector set is made only after
/// run-time detection ([`Avx2::new`], [`Avx512::new`]) or by [`Isa::dispatch`] for a set it
/// checked, so vector code that holds one may use the set's intrinsics: it is sound by
/// construction, not by convention.
pub trait Token: Copy + Send + Sync + 'static {
    /// The set this token stands for.
    const ISA: Isa;
    /// This token as an AVX-512 one, if it is one (for kernels with AVX-512-only forms; a
    /// constant after monomorphisation).
    #[inline(always)]
    fn avx512(self) -> Option<Avx512> {
        None
    }
    /// This token as an AVX2 one, if it is one.
    #[inline(always)]
    fn avx2(self) -> Option<Avx2> {
        None
    }
}

/// The token of plain code: every CPU runs it.
#[derive(Clone, Copy, Debug)]
pub struct Portable;

/// The token of AVX2 (see [`Token`]).
#[derive(Clone, Copy, Debug)]
pub struct Avx2(());

/// The token of AVX-512 F, BW, DQ and VL (see [`Token`]).
#[derive(Clone, Copy, Debug)]
pub struct Avx512(());

impl Token for Portable {
    const ISA: Isa = Isa::Portable;
}

impl Token for Avx2 {
    const ISA: Isa = Isa::Avx2;
    #[inline(always)]
    fn avx2(self) -> Option<Avx2> {
        Some(self)
    }
}

impl Token for Avx512 {
    const ISA: Isa = Isa::Avx512;
    #[inline(always)]
    fn avx512(self) -> Option<Avx512> {
        Some(self)
    }
}

impl Avx2 {
    /// The token, if this CPU runs AVX2.
    pub fn new() -> Option<Self> {
        (Isa::detect() >= Isa::Avx2).then_some(Avx2(()))
    }
}

impl Avx512 {
    /// The token, if this CPU runs AVX-512 F, BW, DQ and VL.
    pub fn new() -> Option<Self> {
        (Isa::detect() >= Isa::Avx512).then_some(Avx512(()))
    }
}

/// Code compiled once per instruction set: [`Isa::dispatch`] calls `run` with the set's token
/// inside a function compiled for that set. Implementations mark `run` `#[inline(always)]`,
/// so that the whole kernel is compiled with the set's features.
pub trait Kernel {
    /// What the kernel returns.
    type Output;
    /// The kernel on the set of token `t`.
    fn run<T: Token>(self, t: T) -> Self::Output;
}

/// An instruction set this CPU runs (made by [`Isa::on_this_cpu`] or [`Cpu::detect`]): what
/// the vector entry points dispatch on without checking again.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cpu(Isa);

impl Cpu {
    /// The widest set this CPU runs.
    pub fn detect() -> Cpu {
        Cpu(Isa::detect())
    }

    /// The set.
    #[inline]
    pub fn isa(self) -> Isa {
        self.0
    }

    /// Run `k` on this set. The only place that enters vector code: one `#[target_feature]`
    /// function per set, each with the set's one feature string.
    #[inline(always)]
    pub fn dispatch<K: Kernel>(self, k: K) -> K::Output {
        match self.0 {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: a `Cpu` holds only sets this CPU runs (see `Isa::on_this_cpu`).
            Isa::Avx512 => unsafe { run_avx512(k, Avx512(())) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            Isa::Avx2 => unsafe { run_avx2(k, Avx2(())) },
            _ => k.run(Portable),
        }
    }
}

impl Isa {
    /// This set as a [`Cpu`] if this CPU runs it.
    pub fn on_this_cpu(self) -> Option<Cpu> {
        (self <= Isa::detect()).then_some(Cpu(self))
    }

    /// [`Isa::supported`] as a [`Cpu`] (any value is safe to dispatch on).
    pub fn cpu(self) -> Cpu {
        Cpu(self.supported())
    }
}

/// [`Kernel::run`] compiled for AVX-512 (the features [`Isa::detect`] checks).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl")]
fn run_avx512<K: Kernel>(k: K, t: Avx512) -> K::Output {
    k.run(t)
}

/// [`Kernel::run`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn run_avx2<K: Kernel>(k: K, t: Avx2) -> K::Output {
    k.run(t)
}

#[cfg(test)]
mod tests {
    use super::Isa;

    #[test]
    fn supported_never_exceeds_the_detected_set() {
        let best = Isa::detect();
        for isa in [Isa::Portable, Isa::Avx2, Isa::Avx512] {
            assert!(isa.supported() <= best);
            assert!(isa.supported() <= isa);
        }
        assert_eq!(Isa::available().last(), Some(&best));
        assert_eq!(Isa::available()[0], Isa::Portable);
    }
}
