//! A baked board's material as a MaterialX document of an OpenPBR Surface (`open_pbr_surface`),
//! for studio and USD pipelines: the baked textures (base colour, normal map, the fibre map as
//! the specular lobe's tangent) and two maps made here, the OpenPBR specular roughness and
//! roughness anisotropy of the fibre lobe, under a coat for the finish.
//!
//! Sources: \[OpenPBR\] Andersson et al., *OpenPBR Surface* specification v1.1 (§ Specular:
//! α_t = r² √(2 / (1 + (1 − a)²)) along the tangent, α_b = (1 − a) α_t; § Coat: the base's
//! specular IOR is taken relative to the coat, η_s / η_c, inverted where below 1); MaterialX 1.39
//! `ND_open_pbr_surface_surfaceshader` and its `NG_open_pbr_anisotropy` graph, which compute the
//! same. \[MTLX\] *MaterialX Specification* v1.39 (document and node syntax; `image`,
//! `normalmap`, `tangent`/`bitangent` geometric nodes; texture coordinates with (0, 0) at the
//! image's lower left). The mapping and its limits are in notes/gltf.md ("MaterialX / OpenPBR").
//!
//! The XML is written by hand (a dozen element kinds, attribute values escaped); the MaterialX
//! Python package validates it in crates/xylem-cli/tests/materialx_export.rs.

use super::gltf::{ggx_alpha_along_fiber, FINISH_IOR};
use super::BakedMaps;
use crate::output::Staged;
use crate::picture::png::{stage_png_tagged, PngTag};
use crate::picture::ImageError;
use std::path::Path;

/// The coat's index of refraction: the finish the bake assumes (`gltf::FINISH_IOR`, 1.5, the
/// scenes' default `eta`), which (G.1) in notes/gltf.md also uses to widen the fibre lobe.
pub const COAT_IOR: f32 = FINISH_IOR;

/// The coat's roughness: the bake's finish is smooth (the scenes' default `roughness = 0`).
pub(crate) const COAT_ROUGHNESS: f32 = 0.0;

/// OpenPBR's `specular_ior`. Under a coat OpenPBR reflects at the base with the ratio
/// η_s / η_c (\[OpenPBR\] § Coat), so η_s = η_c would remove the fibre highlight entirely. The
/// fibre lobe is no Fresnel interface; it is given the ratio 1.5 (F0 = 0.04 under the coat),
/// the strength the `.glb` gives it in air, so both exports show the same lobe.
pub(crate) const SPECULAR_IOR: f32 = COAT_IOR * 1.5;

/// File names of the maps the document reads, relative to the document's folder.
pub(crate) const BASE_COLOR_PNG: &str = "base_color.png";
/// The tangent-space normal map (0.5 + 0.5 n, linear).
pub(crate) const NORMAL_PNG: &str = "normal.png";
/// The KHR_materials_anisotropy map: red, green = the direction across the fibre.
pub(crate) const ANISOTROPY_PNG: &str = "anisotropy.png";
/// OpenPBR `specular_roughness` per texel (grey, linear), made by [`stage_materialx`].
pub(crate) const ROUGHNESS_PNG: &str = "openpbr_specular_roughness.png";
/// OpenPBR `specular_roughness_anisotropy` per texel (grey, linear), made by [`stage_materialx`].
pub(crate) const ROUGHNESS_ANISOTROPY_PNG: &str = "openpbr_specular_anisotropy.png";

/// OpenPBR's (`specular_roughness`, `specular_roughness_anisotropy`) for the fibre lobe of width
/// `beta` (radians) whose fibre lies in the face with `strength` (the anisotropy texel's blue).
///
/// Targets: along the fibre α_b = (G.1) (notes/gltf.md, `gltf::ggx_alpha_along_fiber`); along the
/// tangent (across the fibre) α_t = mix(α_b, 1, s²), as KHR_materials_anisotropy gives the `.glb`.
/// Inverting \[OpenPBR\]'s α_t = r² √(2 / (1 + (1 − a)²)), α_b = (1 − a) α_t:
/// 1 − a = α_b / α_t and r = ((α_t² + α_b²) / 2)^¼. Both α clamp to [10⁻⁴, 1].
pub fn openpbr_specular(beta: f32, strength: f32) -> (f32, f32) {
    let a_b = ggx_alpha_along_fiber(beta);
    let a_b = if a_b.is_finite() {
        a_b.clamp(1e-4, 1.0)
    } else {
        1.0
    };
    let s2 = if strength.is_finite() {
        strength.clamp(0.0, 1.0).powi(2)
    } else {
        0.0
    };
    let a_t = a_b + (1.0 - a_b) * s2;
    let roughness = ((a_t * a_t + a_b * a_b) / 2.0).sqrt().sqrt();
    (roughness, 1.0 - a_b / a_t)
}

/// Errors while writing the MaterialX document, naming the file.
#[derive(Debug, thiserror::Error)]
pub enum MaterialXError {
    /// A map could not be encoded or staged.
    #[error("MaterialX map: {0}")]
    Image(#[from] ImageError),
    /// The document could not be written.
    #[error("cannot write MaterialX document {path}: {source}")]
    Io {
        /// The `.mtlx` file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The material's name is empty.
    #[error("MaterialX material name: must not be empty")]
    EmptyName,
}

/// A valid MaterialX element name made from `name` (\[MTLX\] "Element names": letters, digits and
/// underscores, not starting with a digit): every other character becomes `_`.
pub(crate) fn element_name(name: &str) -> String {
    let mut s: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert(0, '_');
    }
    s
}

/// The name of the `surfacematerial` in the document for preset `name` (`M_<name>`), which the
/// USD stage references.
pub(crate) fn material_name(name: &str) -> String {
    format!("M_{}", element_name(name))
}

/// `s` escaped for an XML attribute value in double quotes.
fn attr(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A float as MaterialX writes values: shortest round-trip decimal.
fn num(v: f32) -> String {
    format!("{v}")
}

/// The `.mtlx` text for preset `name`, reading the maps by the file names above (relative to the
/// document). Deterministic: the same name gives the same bytes.
pub(crate) fn materialx_document(name: &str) -> Result<String, MaterialXError> {
    if name.is_empty() {
        return Err(MaterialXError::EmptyName);
    }
    let n = element_name(name);
    let mut x = String::new();
    let mut w = |s: &str| {
        x.push_str(s);
        x.push('\n');
    };
    w(r#"<?xml version="1.0"?>"#);
    w(r#"<materialx version="1.39">"#);
    w(&format!(
        "  <!-- xylem bake: preset {} as an OpenPBR Surface. Mapping and limits: notes/gltf.md. -->",
        attr(name).replace("--", "- -")
    ));
    w(&nodegraph(&n));
    w(&surface_shader(&n));
    w(&format!(
        r#"  <surfacematerial name="{}" type="material">"#,
        material_name(name)
    ));
    w(&format!(
        r#"    <input name="surfaceshader" type="surfaceshader" nodename="SR_{n}" />"#
    ));
    w("  </surfacematerial>");
    w("</materialx>");
    Ok(x)
}

/// The node graph `NG_{n}`: the baked maps as image nodes, the normal map, and the tangent
/// across the fibre from the anisotropy map, with one output per shader input they feed.
fn nodegraph(n: &str) -> String {
    let mut x = String::new();
    let mut w = |s: &str| {
        x.push_str(s);
        x.push('\n');
    };
    w(&format!(r#"  <nodegraph name="NG_{n}">"#));
    let image = |node: &str, ty: &str, file: &str, colorspace: Option<&str>| {
        let cs = colorspace.map_or(String::new(), |c| format!(r#" colorspace="{c}""#));
        format!(
            "    <image name=\"{node}\" type=\"{ty}\">\n      <input name=\"file\" type=\"filename\" value=\"{}\"{cs} />\n    </image>",
            attr(file)
        )
    };
    w(&image(
        "base_color",
        "color3",
        BASE_COLOR_PNG,
        Some("srgb_texture"),
    ));
    w(&image("specular_roughness", "float", ROUGHNESS_PNG, None));
    w(&image(
        "specular_anisotropy",
        "float",
        ROUGHNESS_ANISOTROPY_PNG,
        None,
    ));
    // The bump: tangent-space normal map → world normal (\[MTLX\] `normalmap`).
    w(&image("normal_texel", "vector3", NORMAL_PNG, None));
    w(r#"    <normalmap name="normal" type="vector3">
      <input name="in" type="vector3" nodename="normal_texel" />
    </normalmap>"#);
    // The tangent: the anisotropy map's red, green = 0.5 + 0.5 (dx, dy), the direction across the
    // fibre in tangent space (x along +u, y along +v); world tangent = normalize(dx T + dy B).
    w(&image(
        "across_fiber_texel",
        "vector3",
        ANISOTROPY_PNG,
        None,
    ));
    w(r#"    <subtract name="across_fiber_centred" type="vector3">
      <input name="in1" type="vector3" nodename="across_fiber_texel" />
      <input name="in2" type="float" value="0.5" />
    </subtract>
    <extract name="across_fiber_x" type="float">
      <input name="in" type="vector3" nodename="across_fiber_centred" />
      <input name="index" type="integer" value="0" />
    </extract>
    <extract name="across_fiber_y" type="float">
      <input name="in" type="vector3" nodename="across_fiber_centred" />
      <input name="index" type="integer" value="1" />
    </extract>
    <tangent name="surface_tangent" type="vector3">
      <input name="space" type="string" value="world" />
    </tangent>
    <bitangent name="surface_bitangent" type="vector3">
      <input name="space" type="string" value="world" />
    </bitangent>
    <multiply name="tangent_part" type="vector3">
      <input name="in1" type="vector3" nodename="surface_tangent" />
      <input name="in2" type="float" nodename="across_fiber_x" />
    </multiply>
    <multiply name="bitangent_part" type="vector3">
      <input name="in1" type="vector3" nodename="surface_bitangent" />
      <input name="in2" type="float" nodename="across_fiber_y" />
    </multiply>
    <add name="across_fiber_world" type="vector3">
      <input name="in1" type="vector3" nodename="tangent_part" />
      <input name="in2" type="vector3" nodename="bitangent_part" />
    </add>
    <normalize name="tangent" type="vector3">
      <input name="in" type="vector3" nodename="across_fiber_world" />
    </normalize>"#);
    for (out, ty, node) in [
        ("base_color_out", "color3", "base_color"),
        ("specular_roughness_out", "float", "specular_roughness"),
        ("specular_anisotropy_out", "float", "specular_anisotropy"),
        ("normal_out", "vector3", "normal"),
        ("tangent_out", "vector3", "tangent"),
    ] {
        w(&format!(
            r#"    <output name="{out}" type="{ty}" nodename="{node}" />"#
        ));
    }
    w("  </nodegraph>");
    x.pop();
    x
}

/// The OpenPBR surface shader `SR_{n}`: constants and inputs from the node graph `NG_{n}`.
fn surface_shader(n: &str) -> String {
    let mut x = String::new();
    let mut w = |s: &str| {
        x.push_str(s);
        x.push('\n');
    };
    w(&format!(
        r#"  <open_pbr_surface name="SR_{n}" type="surfaceshader">"#
    ));
    let from_graph = |input: &str, ty: &str, out: &str| {
        format!(r#"    <input name="{input}" type="{ty}" nodegraph="NG_{n}" output="{out}" />"#)
    };
    let value = |input: &str, v: f32| {
        format!(
            r#"    <input name="{input}" type="float" value="{}" />"#,
            num(v)
        )
    };
    w(&value("base_weight", 1.0));
    w(&from_graph("base_color", "color3", "base_color_out"));
    w(&value("base_diffuse_roughness", 0.0));
    w(&value("base_metalness", 0.0));
    w(&value("specular_weight", 1.0));
    w(r#"    <input name="specular_color" type="color3" value="1, 1, 1" />"#);
    w(&from_graph(
        "specular_roughness",
        "float",
        "specular_roughness_out",
    ));
    w(&value("specular_ior", SPECULAR_IOR));
    w(&from_graph(
        "specular_roughness_anisotropy",
        "float",
        "specular_anisotropy_out",
    ));
    w(&value("coat_weight", 1.0));
    w(r#"    <input name="coat_color" type="color3" value="1, 1, 1" />"#);
    w(&value("coat_roughness", COAT_ROUGHNESS));
    w(&value("coat_ior", COAT_IOR));
    w(&from_graph("geometry_normal", "vector3", "normal_out"));
    w(&from_graph("geometry_tangent", "vector3", "tangent_out"));
    w("  </open_pbr_surface>");
    x.pop();
    x
}

/// Grey 8-bit linear codes of `v` in [0, 1] (round(255 v) in R, G and B).
fn grey8(v: impl Iterator<Item = f32>) -> Vec<u8> {
    v.flat_map(|x| [(x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8; 3])
        .collect()
}

/// Stages the OpenPBR roughness and anisotropy maps ([`openpbr_specular`] per texel, linear,
/// untagged) and `DIR/<name>.mtlx`, to commit with the other bake outputs
/// ([`crate::output::commit_set`]). The document also reads `base_color.png`, `normal.png` and
/// `anisotropy.png`, which [`super::stage_maps`] stages.
pub fn stage_materialx(
    dir: &Path,
    maps: &BakedMaps,
    name: &str,
) -> Result<Vec<Staged>, MaterialXError> {
    let (w, h) = (maps.width, maps.height);
    let spec: Vec<(f32, f32)> = maps
        .highlight_width
        .iter()
        .zip(&maps.anisotropy)
        .map(|(&b, a)| openpbr_specular(b, a.z))
        .collect();
    let mut out = Vec::new();
    for (file, bytes) in [
        (ROUGHNESS_PNG, grey8(spec.iter().map(|s| s.0))),
        (ROUGHNESS_ANISOTROPY_PNG, grey8(spec.iter().map(|s| s.1))),
    ] {
        out.push(stage_png_tagged(
            &dir.join(file),
            w,
            h,
            &bytes,
            PngTag::Untagged,
        )?);
    }
    let path = dir.join(format!("{name}.mtlx"));
    let doc = materialx_document(name)?;
    out.push(
        crate::output::stage_bytes(&path, doc.as_bytes()).map_err(|source| MaterialXError::Io {
            path: path.display().to_string(),
            source,
        })?,
    );
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// \[OpenPBR\]'s α pair of (r, a), as `NG_open_pbr_anisotropy` computes it.
    fn alphas(r: f32, a: f32) -> (f32, f32) {
        let at = r * r * (2.0 / (1.0 + (1.0 - a).powi(2))).sqrt();
        (at, (1.0 - a) * at)
    }

    #[test]
    fn openpbr_specular_gives_the_gltf_alphas() {
        for beta in [2f32, 8.0, 16.0, 30.0] {
            let beta = beta.to_radians();
            let ab = ggx_alpha_along_fiber(beta).min(1.0);
            for s in [0.0, 0.3, 0.7, 1.0] {
                let (r, a) = openpbr_specular(beta, s);
                assert!((0.0..=1.0).contains(&r) && (0.0..=1.0).contains(&a));
                let (at, ab2) = alphas(r, a);
                let want = ab + (1.0 - ab) * s * s;
                assert!(
                    (at - want).abs() < 1e-5,
                    "β {beta} s {s}: α_t {at} vs {want}"
                );
                assert!((ab2 - ab).abs() < 1e-5, "β {beta} s {s}: α_b {ab2} vs {ab}");
            }
        }
        // β = 8°: α_b = 0.192 (notes/gltf.md), in-face fibre: α_t = 1.
        let (r, a) = openpbr_specular(8f32.to_radians(), 1.0);
        assert!(
            (a - 0.808).abs() < 2e-3 && (r - 0.849).abs() < 2e-3,
            "{r} {a}"
        );
        // End grain: isotropic at α_b. Nonsense stays in range.
        assert_eq!(openpbr_specular(0.1, 0.0).1, 0.0);
        for (b, s) in [
            (f32::NAN, 1.0),
            (1.0, f32::NAN),
            (-1.0, 2.0),
            (f32::INFINITY, 0.5),
        ] {
            let (r, a) = openpbr_specular(b, s);
            assert!(
                (0.0..=1.0).contains(&r) && (0.0..=1.0).contains(&a),
                "{b} {s}"
            );
        }
    }

    #[test]
    fn the_document_is_deterministic_and_names_are_valid() {
        let d = materialx_document("curly_maple").unwrap();
        assert_eq!(d, materialx_document("curly_maple").unwrap());
        assert!(d.contains(r#"<open_pbr_surface name="SR_curly_maple" type="surfaceshader">"#));
        assert!(d.contains(r#"<input name="coat_ior" type="float" value="1.5" />"#));
        assert!(d.contains(r#"<surfacematerial name="M_curly_maple""#));
        assert_eq!(element_name("9 a-b&c"), "_9_a_b_c");
        assert!(materialx_document("").is_err());
        let odd = materialx_document("a\"<b>--c").unwrap();
        assert!(odd.contains("SR_a__b___c") && !odd.contains("<b>"));
    }
}
