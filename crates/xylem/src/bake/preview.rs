//! A quick look at a mesh bake (`xylem bake --mesh … --preview`): the mesh drawn with its baked
//! maps as a glTF viewer would read them — base colour and the tangent-space normal map looked up
//! bilinearly at the interpolated UV, the vertex tangent frame carrying the normal map — under
//! one distant light, Lambertian only (no fibre highlight: this shows how the wood's figure lies on
//! the surface and whether seams show, not the finish). A z-buffered rasteriser with
//! perspective-correct interpolation (Heckbert & Moreton, "Interpolation for Polygon Texture
//! Mapping and Shading", 1991: attributes / w are linear in screen space).

use super::uv_mesh::UvMesh;
use super::BakedMaps;
use glam::{Vec2, Vec3};

/// Grey of pixels the mesh does not cover (linear).
const BACKGROUND: f32 = 0.03;

/// Draws `mesh` (object space, z up) with `maps`, seen from the front (−y), 30° above, framing
/// its bounding sphere. Returns linear RGB, row-major, `width` × `height`.
pub fn preview(mesh: &UvMesh, maps: &BakedMaps, width: u32, height: u32) -> Vec<Vec3> {
    let (w, h) = (width.max(1) as usize, height.max(1) as usize);
    let mut rgb = vec![Vec3::splat(BACKGROUND); w * h];
    if mesh.positions.is_empty() {
        return rgb;
    }
    let lo = mesh.positions.iter().fold(Vec3::MAX, |a, p| a.min(*p));
    let hi = mesh.positions.iter().fold(Vec3::MIN, |a, p| a.max(*p));
    let (centre, radius) = ((lo + hi) * 0.5, ((hi - lo) * 0.5).length().max(1e-6));
    let fov = 30f32.to_radians();
    let dir = Vec3::new(0.0, -1.0, 0.6).normalize();
    let eye = centre + dir * radius / (0.5 * fov).sin();
    // Camera basis: forward, right, up (z up in object space).
    let fwd = (centre - eye).normalize();
    let right = fwd.cross(Vec3::Z).normalize_or(Vec3::X);
    let up = right.cross(fwd);
    let focal = 0.5 * h as f32 / (0.5 * fov).tan();
    let light = Vec3::new(-0.4, -0.7, 0.8).normalize();
    let tangents = mesh.tangents();
    let mut depth = vec![f32::INFINITY; w * h];
    for t in &mesh.indices {
        // Screen position (pixels, y down) and view depth of each corner.
        let s = t.map(|i| {
            let d = mesh.positions[i as usize] - eye;
            let z = d.dot(fwd);
            Vec3::new(
                0.5 * w as f32 + focal * d.dot(right) / z,
                0.5 * h as f32 - focal * d.dot(up) / z,
                z,
            )
        });
        if s.iter().any(|v| v.z <= 1e-3 * radius) {
            continue;
        }
        let inv_w = s.map(|v| 1.0 / v.z);
        let (a, b, cc) = (s[0].truncate(), s[1].truncate(), s[2].truncate());
        let det = (b - a).perp_dot(cc - a);
        if det.abs() < 1e-12 {
            continue;
        }
        let x0 = a.x.min(b.x).min(cc.x).floor().max(0.0) as usize;
        let y0 = a.y.min(b.y).min(cc.y).floor().max(0.0) as usize;
        let x1 = (a.x.max(b.x).max(cc.x).ceil() as usize).min(w);
        let y1 = (a.y.max(b.y).max(cc.y).ceil() as usize).min(h);
        for y in y0..y1 {
            for x in x0..x1 {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let l1 = (p - a).perp_dot(cc - a) / det;
                let l2 = (b - a).perp_dot(p - a) / det;
                let l = Vec3::new(1.0 - l1 - l2, l1, l2);
                if l.min_element() < 0.0 {
                    continue;
                }
                let z = l.x * s[0].z + l.y * s[1].z + l.z * s[2].z;
                let i = y * w + x;
                if z >= depth[i] {
                    continue;
                }
                depth[i] = z;
                // Perspective-correct barycentrics.
                let q = l * Vec3::from(inv_w);
                let q = q / q.element_sum();
                let at = |v: &dyn Fn(usize) -> Vec3| {
                    v(t[0] as usize) * q.x + v(t[1] as usize) * q.y + v(t[2] as usize) * q.z
                };
                let uv = at(&|k| mesh.uvs[k].extend(0.0)).truncate();
                let n = at(&|k| mesh.normals[k]).normalize_or(Vec3::Z);
                let tg = at(&|k| tangents[k].truncate());
                let tg = (tg - n * n.dot(tg)).normalize_or(n.any_orthonormal_vector());
                let bt = tangents[t[0] as usize].w * n.cross(tg);
                let texel = maps.lookup(uv);
                let nm = texel.normal;
                let mut ns = (tg * nm.x + bt * nm.y + n * nm.z).normalize_or(n);
                // Light the side facing the camera (the bowl's inside is seen from within).
                if ns.dot(eye - at(&|k| mesh.positions[k])) < 0.0 {
                    ns = -ns;
                }
                rgb[i] = texel.base_color * (0.15 + 0.85 * ns.dot(light).max(0.0));
            }
        }
    }
    rgb
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quad_fills_the_middle_of_the_view_with_its_texels() {
        let m = UvMesh::from_trimesh(
            crate::scene::shapes::make_quad(Vec2::new(100.0, 100.0)),
            vec![
                Vec2::new(0.0, 1.0),
                Vec2::ONE,
                Vec2::new(1.0, 0.0),
                Vec2::ZERO,
            ],
        )
        .unwrap();
        let maps = BakedMaps {
            width: 1,
            height: 1,
            base_color: vec![Vec3::ONE],
            fiber_color: vec![Vec3::ONE],
            anisotropy: vec![Vec3::new(0.5, 1.0, 1.0)],
            highlight_width: vec![0.1],
            ray_mask: vec![0.0],
            normal: vec![Vec3::Z],
            fiber: vec![Vec3::X],
            ray: vec![Vec3::Y],
        };
        let px = preview(&m, &maps, 40, 30);
        let mid = px[15 * 40 + 20];
        assert!(mid.x > BACKGROUND && mid.x <= 1.0, "{mid}");
        assert_eq!(px[0], Vec3::splat(BACKGROUND));
    }
}
