//! Wood texels as bits, for the bit-for-bit tests (`#[path = "common/texel.rs"] mod texel;`).

/// Every field of a wood texel as its f32 bits (vectors first, then scalars), for bit-for-bit
/// comparisons.
pub fn texel_bits(t: &xylem::wood::WoodTexel) -> Vec<u32> {
    let mut v = Vec::new();
    for x in [
        t.diffuse,
        t.fiber_color,
        t.fiber_dir,
        t.ray_dir,
        t.bump_grad,
    ] {
        v.extend(x.to_array().map(f32::to_bits));
    }
    for x in [
        t.ray_mask,
        t.pore_mask,
        t.bump,
        t.highlight_width,
        t.growth_time,
    ] {
        v.push(x.to_bits());
    }
    v
}
