// The ordered dither the cross-fades between representations share: each pixel of a fading
// band shows one of the two, the mix moving smoothly with distance.

// Ordered dither threshold of a pixel, in (0, 1), the pattern shifted by `shift` (0 to 15).
fn bayer4(pixel: vec2<u32>, shift: u32) -> f32 {
    let m = array<u32, 16>(0u, 8u, 2u, 10u, 12u, 4u, 14u, 6u, 3u, 11u, 1u, 9u, 15u, 7u, 13u, 5u);
    let p = pixel + vec2<u32>(shift & 3u, shift >> 2u);
    return (f32(m[(p.y & 3u) * 4u + (p.x & 3u)]) + 0.5) / 16.0;
}
