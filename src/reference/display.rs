//! Twin of the display pass (`shaders/display.wgsl`): the frame's balanced light exposed to a
//! physical scale and brought through the tone curve, in f32 as the shader computes it. Its
//! tests hold the curves to what their authors publish.

use glam::Vec3;

use crate::config::ToneCurve;
use crate::gpu::gpu_types::DisplayUniforms;
use crate::gpu::layout::{HOST_HDR_MAX, SCENE_LIGHT_MAX};

fn by_rows(rows: &[[f32; 4]; 3], v: Vec3) -> Vec3 {
    let row = |r: &[f32; 4]| Vec3::new(r[0], r[1], r[2]).dot(v);
    Vec3::new(row(&rows[0]), row(&rows[1]), row(&rows[2]))
}

fn agx(u: &DisplayUniforms, x: Vec3) -> Vec3 {
    let [c0, c1] = u.coefficients;
    let powers = [c0[0], c0[1], c0[2], c0[3], c1[0], c1[1], c1[2]];
    let [low, high, ..] = u.encoding;
    let encoded =
        x.max(Vec3::splat(1e-10)).to_array().map(|v| (v.log2().clamp(low, high) - low) / (high - low));
    let encoded = Vec3::from_array(encoded);
    powers[..6].iter().rev().fold(Vec3::splat(powers[6]), |y, &c| y * encoded + c)
}

fn aces(u: &DisplayUniforms, x: Vec3) -> Vec3 {
    let [[a, b, c, d], [e, ..]] = u.coefficients;
    (x * (x + a) - b) / (x * (c * x + d) + e)
}

/// The curve `curve` (whose constants `u` holds) of light already exposed: linear display light.
pub fn tone(u: &DisplayUniforms, curve: ToneCurve, exposed: Vec3) -> Vec3 {
    let into = by_rows(&u.into_curve, exposed);
    match curve {
        ToneCurve::Agx => {
            by_rows(&u.out_of_curve, agx(u, into)).clamp(Vec3::ZERO, Vec3::ONE).powf(u.encoding[2])
        }
        ToneCurve::Aces => by_rows(&u.out_of_curve, aces(u, into)).clamp(Vec3::ZERO, Vec3::ONE),
        ToneCurve::Linear => into.clamp(Vec3::ZERO, Vec3::ONE),
    }
}

/// `shown`: the linear display light of the frame's balanced light `balanced`, the daylight
/// balance being `daylight` (`reference::atmosphere::light::daylight_balance`).
pub fn shown(u: &DisplayUniforms, curve: ToneCurve, daylight: Vec3, balanced: Vec3) -> Vec3 {
    if curve == ToneCurve::Linear {
        return balanced.clamp(Vec3::ZERO, Vec3::ONE);
    }
    tone(u, curve, exposed(u, daylight, balanced))
}

/// The frame's balanced light `balanced` exposed: scene-referred linear light (sRGB primaries)
/// that a tone curve takes, mid grey 0.18 at the exposure (`display.ev100`).
pub fn exposed(u: &DisplayUniforms, daylight: Vec3, balanced: Vec3) -> Vec3 {
    let weights = Vec3::new(u.luminance[0], u.luminance[1], u.luminance[2]);
    let daylight_luminance = weights.dot(Vec3::ONE / daylight);
    balanced.min(Vec3::splat(SCENE_LIGHT_MAX)).max(Vec3::ZERO) * (daylight_luminance * u.exposure[0])
}

/// `fs_display_over_linear` and its blend: the exposed light (at most `HOST_HDR_MAX`) over a
/// host's linear HDR pixel `under`, the frame's light being `light` premultiplied by its coverage
/// `alpha`.
pub fn exposed_over(u: &DisplayUniforms, daylight: Vec3, (light, alpha): (Vec3, f32), under: Vec3) -> Vec3 {
    if alpha <= 0.0 {
        return under;
    }
    exposed(u, daylight, light / alpha).min(Vec3::splat(HOST_HDR_MAX)) * alpha + under * (1.0 - alpha)
}

/// `fs_display_over` and its blend: the linear display light over a host's pixel whose linear
/// colour is `under`, the frame's light being `light` premultiplied by its coverage `alpha`.
pub fn shown_over(
    u: &DisplayUniforms,
    curve: ToneCurve,
    daylight: Vec3,
    (light, alpha): (Vec3, f32),
    under: Vec3,
) -> Vec3 {
    if alpha <= 0.0 {
        return under;
    }
    shown(u, curve, daylight, light / alpha) * alpha + under * (1.0 - alpha)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::DisplaySettings;
    use crate::passes::display::{MID_GREY, uniforms};
    use crate::texcell::pyramid::encode_srgb;

    fn curve(tone_curve: ToneCurve) -> DisplayUniforms {
        uniforms(&DisplaySettings { ev100: 15.0, tone_curve })
    }

    fn encoded(curve: ToneCurve, x: f32) -> f32 {
        let shown = tone(&self::curve(curve), curve, Vec3::splat(x));
        f32::from(encode_srgb(shown.y)) / 255.0
    }

    #[test]
    fn the_aces_fit_shows_grey_where_the_reference_transforms_do() {
        // ACES's reference rendering and sRGB output transforms (RRT + ODT) show scene grey 1.0
        // at 0.812 of the sRGB code range, and reach white at about 16.3 (acescentral.com,
        // "Understanding the sRGB RRT/ODT"); Hill's fit within 0.01 of both.
        let one = encoded(ToneCurve::Aces, 1.0);
        assert!((one - 0.812).abs() < 0.01, "{one}");
        let white = encoded(ToneCurve::Aces, 16.292);
        assert!(white > 0.99, "{white}");
    }

    #[test]
    fn agx_puts_mid_grey_mid_display_and_spans_sixteen_and_a_half_stops() {
        let grey = encoded(ToneCurve::Agx, MID_GREY as f32);
        assert!((grey - 0.5).abs() < 0.01, "{grey}");
        // 10 stops under mid-grey is black, 6.5 over it white, within a level or two of 8 bits.
        let black = encoded(ToneCurve::Agx, (MID_GREY as f32) * (-10.0f32).exp2());
        let white = encoded(ToneCurve::Agx, (MID_GREY as f32) * 6.5f32.exp2());
        assert!(black < 0.03 && white > 0.98, "{black} {white}");
    }

    #[test]
    fn both_curves_rise_from_black_to_white_and_keep_grey_grey() {
        for c in [ToneCurve::Agx, ToneCurve::Aces] {
            let u = curve(c);
            let mut last = -1.0;
            for k in -40..=40 {
                let x = (k as f32 * 0.25).exp2();
                let shown = tone(&u, c, Vec3::splat(x));
                assert!(shown.y >= last, "{}: {x}", c.name());
                assert!(
                    (shown.x - shown.y).abs() < 2e-3 && (shown.z - shown.y).abs() < 2e-3,
                    "{}: {shown}",
                    c.name()
                );
                last = shown.y;
            }
            assert!(tone(&u, c, Vec3::ZERO).max_element() < 1e-3, "{}", c.name());
            assert!(last <= 1.0 && last > 0.97, "{}: {last}", c.name());
        }
    }
}
