//! Random numbers: the Park-Miller minimal standard generator LAMMPS uses
//! (`RanPark`), so seeded insertions are reproducible and platform-independent.

/// Park-Miller generator (a = 16807, m = 2^31 - 1, Schrage's method).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Park {
    seed: i64,
    /// The second value of the last Gaussian pair, not yet returned.
    second: Option<f64>,
}

const IA: i64 = 16807;
const IM: i64 = 2147483647;
const IQ: i64 = 127773;
const IR: i64 = 2836;

impl Park {
    /// A generator; seeds <= 0 are mapped to 1.
    pub fn new(seed: i64) -> Park {
        let s = seed.rem_euclid(IM);
        Park { seed: if s == 0 { 1 } else { s }, second: None }
    }
    /// LAMMPS `RanPark::reset(ibase, coord)`: a generator seeded from a
    /// seed and a point, so that an atom's draw does not depend on which
    /// process owns it (`set type/fraction`). Jenkins' one-at-a-time hash
    /// over the bytes of the 32-bit seed and the three doubles as they lie in
    /// memory (little-endian), each byte added as a signed char; the seed is
    /// the hash's low 27 bits (0 -> 1), then five draws are discarded.
    pub fn from_point(seed: i32, x: [f64; 3]) -> Park {
        let mut hash: u32 = 0;
        let mut mix = |b: u8| {
            hash = hash.wrapping_add(b as i8 as i32 as u32);
            hash = hash.wrapping_add(hash << 10);
            hash ^= hash >> 6;
        };
        seed.to_le_bytes().into_iter().for_each(&mut mix);
        x.iter().flat_map(|c| c.to_le_bytes()).for_each(&mut mix);
        hash = hash.wrapping_add(hash << 3);
        hash ^= hash >> 11;
        hash = hash.wrapping_add(hash << 15);
        let s = (hash & 0x7ffffff) as i64;
        let mut p = Park { seed: if s == 0 { 1 } else { s }, second: None };
        for _ in 0..5 {
            p.uniform();
        }
        p
    }
    /// A standard normal value: Marsaglia's polar method, two uniform draws
    /// per pair, the pair's second value kept for the next call (LAMMPS
    /// `RanPark::gaussian`, so velocities created from a seed match lmp's).
    pub fn gaussian(&mut self) -> f64 {
        if let Some(v) = self.second.take() {
            return v;
        }
        let (v1, v2, rsq) = loop {
            let v1 = 2.0 * self.uniform() - 1.0;
            let v2 = 2.0 * self.uniform() - 1.0;
            let rsq = v1 * v1 + v2 * v2;
            if rsq < 1.0 && rsq != 0.0 {
                break (v1, v2, rsq);
            }
        };
        let fac = (-2.0 * rsq.ln() / rsq).sqrt();
        self.second = Some(v1 * fac);
        v2 * fac
    }
    /// Uniform in (0, 1): the state times 1/m, multiplied by the reciprocal
    /// as `RanPark::uniform` does (`AM*seed`); dividing by m rounds
    /// differently for some states.
    pub fn uniform(&mut self) -> f64 {
        let k = self.seed / IQ;
        self.seed = IA * (self.seed - k * IQ) - IR * k;
        if self.seed < 0 {
            self.seed += IM;
        }
        (1.0 / IM as f64) * self.seed as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn minimal_standard_sequence() {
        // Park & Miller (1988): from seed 1 the 10000th value is 1043618065.
        let mut p = Park::new(1);
        for _ in 0..9999 {
            p.uniform();
        }
        let v = p.uniform();
        assert!((v * IM as f64 - 1043618065.0).abs() < 0.5, "{}", v * IM as f64);
    }

    #[test]
    fn gaussian_pairs_have_unit_variance_and_reuse_the_second_value() {
        let mut p = Park::new(4711);
        let n = 200_000;
        let draws: Vec<f64> = (0..n).map(|_| p.gaussian()).collect();
        let mean = draws.iter().sum::<f64>() / n as f64;
        let var = draws.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n as f64;
        assert!(mean.abs() < 0.01 && (var - 1.0).abs() < 0.01, "mean {mean} variance {var}");
        // the first two values are the first accepted pair of uniform draws
        // scaled, v2's first and v1's kept for the second call
        let mut q = Park::new(4711);
        let (v1, v2, rsq) = loop {
            let (v1, v2) = (2.0 * q.uniform() - 1.0, 2.0 * q.uniform() - 1.0);
            if v1 * v1 + v2 * v2 < 1.0 {
                break (v1, v2, v1 * v1 + v2 * v2);
            }
        };
        let fac = (-2.0 * rsq.ln() / rsq).sqrt();
        assert_eq!((draws[0], draws[1]), (v2 * fac, v1 * fac));
    }
}
