//! Which build of the multiversioned kernels this processor runs: the score
//! terms (`batch.rs`, eq. 1, 4, 5), the scan's cell keys (`pairs.rs`), the
//! moments (`moments.rs`) and an inserted scan's points and cells
//! (`staging.rs`, eq. 2) each come in an AVX-512, an AVX2 and a NEON build
//! besides the generic one, picked at run time. Benchmarks report it beside
//! the processor, since the same code runs at different speeds on each.

use multiversion::multiversion;
use multiversion::target::selected_target;

/// The vector extension of one build of the kernels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VectorExtension {
    /// x86-64 with AVX-512 (F, DQ, VL), AVX2 and FMA.
    Avx512,
    /// x86-64 with AVX2 and FMA.
    Avx2,
    /// AArch64 with NEON.
    Neon,
}

impl VectorExtension {
    /// Its usual name: `"AVX-512"`, `"AVX2"` or `"NEON"`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Avx512 => "AVX-512",
            Self::Avx2 => "AVX2",
            Self::Neon => "NEON",
        }
    }
}

/// The vector extension of the kernels' build that runs here, `None` for
/// the generic build. The targets are the kernels' own, in their order, so
/// the choice is theirs (a test checks that the four lists are the same;
/// a macro holding the list would keep rustfmt out of the kernels' bodies).
#[multiversion(targets(
    "x86_64+avx512f+avx512dq+avx512vl+avx2+fma+avx",
    "x86_64+avx2+fma+avx",
    "aarch64+neon"
))]
pub fn vector_extension() -> Option<VectorExtension> {
    let target = selected_target!();
    if target.supports_feature_str("avx512f") {
        Some(VectorExtension::Avx512)
    } else if target.supports_feature_str("avx2") {
        Some(VectorExtension::Avx2)
    } else if target.supports_feature_str("neon") {
        Some(VectorExtension::Neon)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `multiversion` targets of a source file, each attribute's list
    /// (attributes at the start of a line).
    fn targets(source: &str) -> Vec<&str> {
        source
            .split("\n#[multiversion(targets(")
            .skip(1)
            .filter_map(|rest| rest.split("))]").next())
            .collect()
    }

    /// The kernels (`batch.rs`, `moments.rs`, `pairs.rs`, `staging.rs`) and
    /// [`vector_extension`] have the same targets, in the same order, so the
    /// build named is the one the kernels run.
    #[test]
    fn the_kernels_and_the_report_share_their_targets() {
        let own = targets(include_str!("kernels.rs"));
        assert_eq!(own.len(), 1);
        for source in [
            include_str!("batch.rs"),
            include_str!("moments.rs"),
            include_str!("pairs.rs"),
            include_str!("staging.rs"),
        ] {
            let theirs = targets(source);
            assert!(!theirs.is_empty());
            assert!(theirs.iter().all(|t| *t == own[0]), "{theirs:?} != {own:?}");
        }
    }

    /// The answer follows the processor's features as the standard library
    /// detects them, target by target in the kernels' order.
    #[test]
    fn the_build_is_the_widest_the_processor_supports() {
        #[cfg(target_arch = "x86_64")]
        let expected = {
            let has = |f: &[bool]| f.iter().all(|&b| b);
            if has(&[
                std::arch::is_x86_feature_detected!("avx512f"),
                std::arch::is_x86_feature_detected!("avx512dq"),
                std::arch::is_x86_feature_detected!("avx512vl"),
                std::arch::is_x86_feature_detected!("avx2"),
                std::arch::is_x86_feature_detected!("fma"),
            ]) {
                Some(VectorExtension::Avx512)
            } else if has(&[
                std::arch::is_x86_feature_detected!("avx2"),
                std::arch::is_x86_feature_detected!("fma"),
            ]) {
                Some(VectorExtension::Avx2)
            } else {
                None
            }
        };
        #[cfg(target_arch = "aarch64")]
        let expected =
            std::arch::is_aarch64_feature_detected!("neon").then_some(VectorExtension::Neon);
        #[cfg(not(any(target_arch = "x86_64", target_arch = "aarch64")))]
        let expected: Option<VectorExtension> = None;
        assert_eq!(vector_extension(), expected);
    }
}
