//! The unit tests' random numbers: Marsaglia's xorshift generators, seeded, so every run and
//! every machine draws the same inputs.

/// xorshift32 (shifts 13, 17, 5).
pub(crate) struct XorShift32(pub u32);

impl XorShift32 {
    pub fn next(&mut self) -> u32 {
        let x = &mut self.0;
        *x ^= *x << 13;
        *x ^= *x >> 17;
        *x ^= *x << 5;
        *x
    }
}

/// xorshift64 (shifts 13, 7, 17).
pub(crate) struct XorShift64(pub u64);

impl XorShift64 {
    pub fn next(&mut self) -> u64 {
        let x = &mut self.0;
        *x ^= *x << 13;
        *x ^= *x >> 7;
        *x ^= *x << 17;
        *x
    }
}
