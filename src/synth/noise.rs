//! How it works: every random quantity of the synthetic world is a pure function of integer
//! lattice coordinates, hashed with a seed-derived salt, so any sample can be evaluated alone, in
//! any order, on any thread, and comes out bit-identical.
//!
//! Heights use gradient (Perlin-style) noise with a quintic fade, evaluated together with its exact
//! gradient. `Field` carries a value with its gradient through sums, products and shaping
//! functions (forward-mode differentiation), so slope and hillshading come from the same
//! evaluation as the height instead of three more evaluations for finite differences. Octaves are
//! rotated and offset against each other so the lattice never shows. Colour detail uses cheaper
//! value noise in f32, where a rounding error only moves a shade.

use std::ops::{Add, Mul, Sub};

/// A scalar field sampled at one point: its value and its gradient along grid x (east) and y
/// (north), per metre.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Field {
    /// The field's value at the point (for the relief, metres above the water).
    pub v: f64,
    /// Its derivative towards grid x (east), per metre.
    pub dx: f64,
    /// Its derivative towards grid y (north), per metre.
    pub dy: f64,
}

impl Field {
    /// Zero everywhere: the neutral start of a sum.
    pub const ZERO: Field = Field { v: 0.0, dx: 0.0, dy: 0.0 };

    /// A field of value `v` everywhere: flat, zero gradient.
    pub const fn constant(v: f64) -> Field {
        Field { v, dx: 0.0, dy: 0.0 }
    }

    /// Steepness: rise over run.
    pub fn slope(self) -> f64 {
        // Not `hypot`: its overflow care is a libm call, and slopes are far from overflow.
        (self.dx * self.dx + self.dy * self.dy).sqrt()
    }

    /// Absolute value, the gradient mirrored where the value is negative (the ridged noise's fold).
    pub fn abs(self) -> Field {
        if self.v < 0.0 { Field { v: -self.v, dx: -self.dx, dy: -self.dy } } else { self }
    }

    /// The field times itself, gradient by the product rule.
    pub fn square(self) -> Field {
        self * self
    }

    /// Clamped to [0, 1]; flat where clamped.
    pub fn saturate(self) -> Field {
        if self.v <= 0.0 {
            Field::ZERO
        } else if self.v >= 1.0 {
            Field::constant(1.0)
        } else {
            self
        }
    }

    /// Hermite step from 0 at `lo` to 1 at `hi`.
    pub fn smoothstep(self, lo: f64, hi: f64) -> Field {
        let t = ((self.v - lo) / (hi - lo)).clamp(0.0, 1.0);
        let slope = 6.0 * t * (1.0 - t) / (hi - lo);
        Field { v: t * t * (3.0 - 2.0 * t), dx: slope * self.dx, dy: slope * self.dy }
    }
}

impl Add for Field {
    type Output = Field;
    fn add(self, o: Field) -> Field {
        Field { v: self.v + o.v, dx: self.dx + o.dx, dy: self.dy + o.dy }
    }
}

impl Sub for Field {
    type Output = Field;
    fn sub(self, o: Field) -> Field {
        Field { v: self.v - o.v, dx: self.dx - o.dx, dy: self.dy - o.dy }
    }
}

impl Mul for Field {
    type Output = Field;
    fn mul(self, o: Field) -> Field {
        Field { v: self.v * o.v, dx: self.dx * o.v + self.v * o.dx, dy: self.dy * o.v + self.v * o.dy }
    }
}

impl Mul<f64> for Field {
    type Output = Field;
    fn mul(self, k: f64) -> Field {
        Field { v: self.v * k, dx: self.dx * k, dy: self.dy * k }
    }
}

impl Add<f64> for Field {
    type Output = Field;
    fn add(self, k: f64) -> Field {
        Field { v: self.v + k, ..self }
    }
}

/// A 32-bit avalanche finalizer (Wellons' lowbias32): every input bit flips about half the output
/// bits, at the cost of two multiplies.
#[inline(always)]
pub fn mix32(mut h: u32) -> u32 {
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^ (h >> 16)
}

/// A salt for one named random stream of one seed.
pub fn salt(seed: u64, stream: u32) -> u32 {
    mix32(mix32(seed as u32 ^ mix32((seed >> 32) as u32)) ^ stream.wrapping_mul(0x9e37_79b9))
}

/// Hash of lattice point (`ix`, `iy`) in the stream `salt`.
#[inline(always)]
pub fn hash2(ix: i64, iy: i64, salt: u32) -> u32 {
    // Odd multipliers keep distinct points distinct before the finalizer mixes them.
    mix32((ix as u32).wrapping_mul(0x8da6_b343) ^ (iy as u32).wrapping_mul(0xd816_3841) ^ salt)
}

/// A hash mapped to [0, 1).
#[inline(always)]
pub fn unit(h: u32) -> f64 {
    f64::from(h >> 8) * (1.0 / 16_777_216.0)
}

/// Integer part and fraction of `x`, without the libm `floor` call that baseline x86-64 needs.
#[inline(always)]
fn split(x: f64) -> (i64, f64) {
    let i = x as i64;
    let i = if (i as f64) > x { i - 1 } else { i };
    (i, x - i as f64)
}

/// `x.floor()` without the libm call.
#[inline(always)]
pub fn floor(x: f64) -> f64 {
    split(x).0 as f64
}

/// `x` modulo `period` in [0, `period`), without the libm `fmod` call.
#[inline(always)]
pub fn wrap(x: f64, period: f64) -> f64 {
    x - floor(x / period) * period
}

/// Sixteen unit gradients, evenly spread so no direction is favoured.
const GRADIENTS: [[f64; 2]; 16] = {
    let mut g = [[0.0; 2]; 16];
    // cos and sin of k·22.5°, written out because const fns cannot call trig.
    let c = [1.0, 0.923_879_532_511_286_7, std::f64::consts::FRAC_1_SQRT_2, 0.382_683_432_365_089_8];
    let mut k = 0;
    while k < 16 {
        let q = k / 4;
        let (cos, sin) = (c[k % 4], if k % 4 == 0 { 0.0 } else { c[4 - k % 4] });
        g[k] = match q {
            0 => [cos, sin],
            1 => [-sin, cos],
            2 => [-cos, -sin],
            _ => [sin, -cos],
        };
        k += 1;
    }
    g
};

/// Gradient noise at lattice coordinates (`x`, `y`), about [-1, 1], with its gradient per lattice
/// unit.
#[inline(always)]
pub fn gradient_noise(x: f64, y: f64, salt: u32) -> Field {
    let (ix, fx) = split(x);
    let (iy, fy) = split(y);
    let g = |i: i64, j: i64| GRADIENTS[(hash2(ix + i, iy + j, salt) >> 28) as usize];
    let (ga, gb, gc, gd) = (g(0, 0), g(1, 0), g(0, 1), g(1, 1));
    let va = ga[0] * fx + ga[1] * fy;
    let vb = gb[0] * (fx - 1.0) + gb[1] * fy;
    let vc = gc[0] * fx + gc[1] * (fy - 1.0);
    let vd = gd[0] * (fx - 1.0) + gd[1] * (fy - 1.0);
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let dfade = |t: f64| 30.0 * t * t * (t * (t - 2.0) + 1.0);
    let (u, v, du, dv) = (fade(fx), fade(fy), dfade(fx), dfade(fy));
    let k = va - vb - vc + vd;
    // Unit gradients keep 2D Perlin noise within ±√½; scale it to about ±1.
    const SCALE: f64 = std::f64::consts::SQRT_2;
    Field {
        v: SCALE * (va + u * (vb - va) + v * (vc - va) + u * v * k),
        dx: SCALE
            * (ga[0]
                + u * (gb[0] - ga[0])
                + v * (gc[0] - ga[0])
                + u * v * (ga[0] - gb[0] - gc[0] + gd[0])
                + du * (vb - va + v * k)),
        dy: SCALE
            * (ga[1]
                + u * (gb[1] - ga[1])
                + v * (gc[1] - ga[1])
                + u * v * (ga[1] - gb[1] - gc[1] + gd[1])
                + dv * (vc - va + u * k)),
    }
}

/// Value noise in [-1, 1] at lattice coordinates (`x`, `y`): cheap, smooth, no gradient. The
/// lattice split is in f64 so large coordinates keep their fraction.
#[inline(always)]
pub fn value_noise(x: f64, y: f64, salt: u32) -> f32 {
    let (ix, fx) = split(x);
    let (iy, fy) = split(y);
    let at = |i: i64, j: i64| (hash2(ix + i, iy + j, salt) >> 8) as f32 * (2.0 / 16_777_216.0) - 1.0;
    let (fx, fy) = (fx as f32, fy as f32);
    let (u, v) = (fx * fx * (3.0 - 2.0 * fx), fy * fy * (3.0 - 2.0 * fy));
    let south = at(0, 0) + (at(1, 0) - at(0, 0)) * u;
    let north = at(0, 1) + (at(1, 1) - at(0, 1)) * u;
    south + (north - south) * v
}

/// One octave's frame: lattice coordinates `u = m · p + offset` of grid position `p` (metres).
#[derive(Debug, Clone, Copy)]
pub struct Octave {
    m: [f64; 4],
    offset: [f64; 2],
    salt: u32,
}

impl Octave {
    /// Octave `index` of a stack whose first octave has wavelength `wavelength_m`, each next one
    /// `lacunarity` times finer and turned by an irrational-looking angle.
    pub fn new(seed: u64, stream: u32, index: u32, wavelength_m: f64, lacunarity: f64) -> Self {
        let salt = salt(seed, stream.wrapping_mul(64).wrapping_add(index));
        let frequency = lacunarity.powi(index as i32) / wavelength_m;
        let angle = 0.6435 * f64::from(index) + 2.0 * std::f64::consts::PI * unit(mix32(salt ^ 1));
        let (sin, cos) = angle.sin_cos();
        // Offsets keep the lattice points (where Perlin noise is 0) of all octaves apart.
        let offset = [1024.0 * unit(mix32(salt ^ 2)), 1024.0 * unit(mix32(salt ^ 3))];
        Self { m: [cos * frequency, -sin * frequency, sin * frequency, cos * frequency], offset, salt }
    }

    /// Gradient noise of this octave at grid position (`x_m`, `y_m`), gradient per metre.
    #[inline(always)]
    pub fn sample(&self, x_m: f64, y_m: f64) -> Field {
        let m = &self.m;
        let u = m[0] * x_m + m[1] * y_m + self.offset[0];
        let v = m[2] * x_m + m[3] * y_m + self.offset[1];
        let n = gradient_noise(u, v, self.salt);
        // Chain rule through the linear map: ∇p = mᵀ ∇u.
        Field { v: n.v, dx: m[0] * n.dx + m[2] * n.dy, dy: m[1] * n.dx + m[3] * n.dy }
    }

    /// Value noise of this octave at grid position (`x_m`, `y_m`).
    #[inline(always)]
    pub fn value(&self, x_m: f64, y_m: f64) -> f32 {
        let m = &self.m;
        let u = m[0] * x_m + m[1] * y_m + self.offset[0];
        let v = m[2] * x_m + m[3] * y_m + self.offset[1];
        value_noise(u, v, self.salt)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradients_are_unit_and_distinct() {
        for (k, g) in GRADIENTS.iter().enumerate() {
            assert!((g[0].hypot(g[1]) - 1.0).abs() < 1e-12, "{k}");
            for h in &GRADIENTS[..k] {
                assert!((g[0] - h[0]).abs() + (g[1] - h[1]).abs() > 0.1);
            }
        }
    }

    #[test]
    fn split_floors_negative_and_positive() {
        assert_eq!(split(2.25), (2, 0.25));
        assert_eq!(split(-2.25), (-3, 0.75));
        assert_eq!(split(-3.0), (-3, 0.0));
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let octave = Octave::new(7, 1, 3, 500.0, 2.0);
        let h = 1e-4;
        for k in 0..200 {
            let (x, y) = (37.1 * f64::from(k) - 900.0, 13.7 * f64::from(k * k % 97));
            let f = octave.sample(x, y);
            let ddx = (octave.sample(x + h, y).v - octave.sample(x - h, y).v) / (2.0 * h);
            let ddy = (octave.sample(x, y + h).v - octave.sample(x, y - h).v) / (2.0 * h);
            assert!((f.dx - ddx).abs() < 1e-6 && (f.dy - ddy).abs() < 1e-6, "{k}: {f:?} {ddx} {ddy}");
            assert!(f.v.abs() <= 1.0 + 1e-9);
        }
    }

    #[test]
    fn field_arithmetic_follows_the_chain_rule() {
        let a = Field { v: 0.3, dx: 2.0, dy: -1.0 };
        let b = Field { v: -0.5, dx: 0.5, dy: 4.0 };
        let p = a * b;
        assert_eq!(p, Field { v: -0.15, dx: 2.0 * -0.5 + 0.3 * 0.5, dy: -1.0 * -0.5 + 0.3 * 4.0 });
        assert_eq!(b.abs(), Field { v: 0.5, dx: -0.5, dy: -4.0 });
        let s = a.smoothstep(0.0, 1.0);
        assert!((s.dx - 6.0 * 0.3 * 0.7 * 2.0).abs() < 1e-12);
    }

    #[test]
    fn value_noise_is_bounded_and_seeded() {
        let mut differs = false;
        for k in 0..1000 {
            let (x, y) = (f64::from(k) * 0.37, f64::from(k % 31) * 1.3);
            let v = value_noise(x, y, 5);
            assert!((-1.0..=1.0).contains(&v));
            differs |= v != value_noise(x, y, 6);
        }
        assert!(differs);
        assert_ne!(salt(1, 0), salt(2, 0));
        assert_ne!(salt(1, 0), salt(1 << 32 | 1, 0));
    }
}
