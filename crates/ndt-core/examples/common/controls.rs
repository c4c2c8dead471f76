//! Work that does not depend on this library, for the timing controls
//! (`machine_control`, `spell_probe`).

/// One xorshift64 step.
#[inline(always)]
pub fn step(mut x: u64) -> u64 {
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    x
}

/// Words per 64-byte line.
pub const WORDS_PER_LINE: usize = 8;

/// A pointer chase through `bytes` of memory: one node per 64-byte line, the
/// nodes in one random cycle (Sattolo's shuffle); `next[at]` is the node
/// after the one at `at` (start at 0).
pub fn chase_cycle(bytes: usize) -> Vec<usize> {
    let n = (bytes / 64).max(2);
    let mut order: Vec<usize> = (0..n).collect();
    let mut r = 12_345_u64;
    for i in (1..n).rev() {
        r = step(r);
        order.swap(i, (r % i as u64) as usize);
    }
    let mut next = vec![0_usize; n * WORDS_PER_LINE];
    for (i, &from) in order.iter().enumerate() {
        let to = order.get((i + 1) % n).copied().unwrap_or(0);
        if let Some(slot) = next.get_mut(from * WORDS_PER_LINE) {
            *slot = to * WORDS_PER_LINE;
        }
    }
    next
}
