//! How it works: the display pass turns the frame's light into the image a screen shows. Every
//! pass that shades draws into a floating-point target (`COLOUR_FORMAT`) in light balanced for
//! daylight: a radiance times π over the light on level ground at sea level under a sun 45° high,
//! channel by channel (`atmosphere::gpu`'s daylight balance), so 1 is white ground in daylight and
//! the photograph's texels keep their values. The display pass reads it back to a physical scale,
//! the luminance it stands for in cd/m² (the sun's illuminance above the air, `SUN_ILLUMINANCE_LX`,
//! is the unit of the atmosphere's light), exposes it as a camera at ISO 100 would at
//! `display.ev100` (the saturation-based exposure, 1 / (1.2 × 2^EV100)), and brings it into the
//! display's range through a named tone curve; the 8-bit sRGB target (`DISPLAY_FORMAT`) encodes it
//! on store. Its twin is `reference::display`.
//!
//! Both curves are a 3 × 3 matrix into the curve's own primaries, a curve per channel, and a
//! matrix back: AgX (Sobotka) as Wrensch's fit has it, a log2 encoding from 10 stops below
//! mid-grey to 6.5 above and a polynomial sigmoid whose output is display-encoded with a 2.2
//! power; ACES's reference rendering and sRGB output transforms as Hill's fit has them, a
//! rational function of linear light. The third, `linear`, shows the frame's light itself,
//! clipped at white, unexposed: what the photograph is measured against.

pub mod gpu;

use glam::Mat3;

use crate::atmosphere::LUMINANCE_OF_LINEAR_SRGB;
use crate::config::{DisplaySettings, ToneCurve};
use crate::gpu::gpu_types::DisplayUniforms;

/// The sun's illuminance above the air, lux: the solar illuminance constant of the daylighting
/// literature (IES; CIE 110), which the atmosphere's unit of light (a sun of irradiance 1) stands
/// for.
pub const SUN_ILLUMINANCE_LX: f64 = 128_000.0;

/// The saturation-based exposure's constant (ISO 12232: 78 / (100 × 0.65)): the luminance that
/// saturates a camera at ISO 100 and EV100 0, cd/m².
pub const SATURATION_CD_M2: f64 = 1.2;

/// Scene mid-grey, the reflectance a light meter aims for: where AgX's log encoding is centred.
pub const MID_GREY: f64 = 0.18;

/// AgX's log encoding: stops below mid-grey and above it.
const AGX_STOPS: [f64; 2] = [10.0, 6.5];

/// AgX's matrix into its primaries (Sobotka's inset, as Wrensch's fit has it), row by row.
const AGX_INSET: [[f32; 3]; 3] = [
    [0.842_479_06, 0.078_433_6, 0.079_223_745],
    [0.042_328_242, 0.878_468_64, 0.079_166_13],
    [0.042_375_655, 0.078_433_6, 0.879_143],
];

/// AgX's sigmoid: a polynomial of the log-encoded light, lowest power first.
const AGX_POLYNOMIAL: [f32; 7] = [-0.002_32, 0.1191, 0.4298, -6.868, 31.96, -40.14, 15.5];

/// The power that takes AgX's output to linear light (its display encoding).
const AGX_DISPLAY_POWER: f32 = 2.2;

/// Hill's fit of ACES: the matrix from linear sRGB into the rendering's working space (with its
/// saturation tweak), row by row.
const ACES_INTO: [[f32; 3]; 3] =
    [[0.59719, 0.35458, 0.04823], [0.07600, 0.90834, 0.01566], [0.02840, 0.13383, 0.83777]];

/// And back to linear sRGB.
const ACES_OUT: [[f32; 3]; 3] =
    [[1.60475, -0.53108, -0.07367], [-0.10208, 1.10813, -0.00605], [-0.00327, -0.07276, 1.07602]];

/// Hill's rational fit of the reference rendering and output transforms, (a, b, c, d, e) in
/// (x (x + a) − b) / (x (c x + d) + e).
const ACES_RATIONAL: [f32; 5] = [0.024_578_6, 0.000_090_537, 0.983_729, 0.432_951, 0.238_081];

/// The display's uniforms for `settings`: the curve's constants and the exposure.
pub fn uniforms(settings: &DisplaySettings) -> DisplayUniforms {
    let rows = |m: Mat3| {
        let t = m.transpose();
        [t.x_axis, t.y_axis, t.z_axis].map(|r| r.extend(0.0).to_array())
    };
    let matrix = |m: [[f32; 3]; 3]| Mat3::from_cols_array_2d(&m).transpose();
    let (into, out, coefficients, encoding) = match settings.tone_curve {
        ToneCurve::Agx => {
            let inset = matrix(AGX_INSET);
            let [below, above] = AGX_STOPS;
            let grey = MID_GREY.log2();
            let mut c = [0.0; 8];
            c[..7].copy_from_slice(&AGX_POLYNOMIAL);
            let encoding = [(grey - below) as f32, (grey + above) as f32, AGX_DISPLAY_POWER, 0.0];
            (inset, inset.inverse(), c, encoding)
        }
        ToneCurve::Aces => {
            let mut c = [0.0; 8];
            c[..5].copy_from_slice(&ACES_RATIONAL);
            (matrix(ACES_INTO), matrix(ACES_OUT), c, [0.0; 4])
        }
        ToneCurve::Linear => (Mat3::IDENTITY, Mat3::IDENTITY, [0.0; 8], [0.0; 4]),
    };
    let weights = LUMINANCE_OF_LINEAR_SRGB.map(|w| w as f32);
    let exposure = SUN_ILLUMINANCE_LX / std::f64::consts::PI / (SATURATION_CD_M2 * settings.ev100.exp2());
    DisplayUniforms {
        into_curve: rows(into),
        out_of_curve: rows(out),
        coefficients: [
            [coefficients[0], coefficients[1], coefficients[2], coefficients[3]],
            [coefficients[4], coefficients[5], coefficients[6], coefficients[7]],
        ],
        encoding,
        luminance: [weights[0], weights[1], weights[2], 0.0],
        exposure: [exposure as f32, 0.0, 0.0, 0.0],
    }
}
