//! Which vector instruction set this CPU runs. The kernels that have wide versions (the
//! 16-ray packet queries, the sample pattern's chunk fills) are compiled once per set and
//! picked at run time, so one binary runs on any x86-64 (and elsewhere, on the portable code).
//! Every version computes the same bits.

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
