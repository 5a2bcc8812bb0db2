//! Peak memory of reading a mesh file, per byte of the file (the factors
//! `xylem::scene::mesh_io::{OBJ,PLY}_PARSE_BYTES_PER_BYTE` the memory check uses; notes/limits.md).
//!
//! `cargo run --release -p xylem-lab --example mesh_parse_peak -- FORMAT N [DIR]`
//!
//! Writes an N×N-vertex grid (2 (N−1)² triangles) as FORMAT — `ply-binary` (x y z nx ny nz
//! floats, triangle faces `uchar int`), `ply-ascii` (the same as text), `ply-quads` (binary,
//! one quad a face: more triangles per byte) or `obj` — into DIR (default: a temporary
//! folder), streamed so that writing holds almost nothing, then reads it with
//! `xylem::scene::mesh_io::load_mesh` and prints the file's size and how far reading raised the
//! peak resident memory (VmHWM over VmRSS before) and the peak address space (VmPeak over
//! VmSize: what `ulimit -v` limits, the vectors' unused doubled capacity included), each also
//! per file byte. Linux only (/proc/self/status).

use std::io::Write;

fn status_kib(field: &str) -> u64 {
    let s = std::fs::read_to_string("/proc/self/status").expect("Linux /proc");
    let line = s.lines().find(|l| l.starts_with(field)).expect(field);
    line[field.len()..]
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .unwrap()
}

/// Writes an `n × n` vertex grid (a gentle bump in z) in `format` to `path`: OBJ, or PLY with
/// binary or ASCII triangles, or binary quads.
fn write_grid(path: &std::path::Path, format: &str, n: u32) {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let vertex = |i: u32, j: u32| {
        let z = ((i * 7 + j * 13) % 17) as f32 / 1700.0;
        [i as f32 / n as f32, j as f32 / n as f32, z]
    };
    let quads = (n - 1) * (n - 1);
    let corners = |q: u32| {
        let (i, j) = (q % (n - 1), q / (n - 1));
        let a = j * n + i;
        [a, a + 1, a + n + 1, a + n]
    };
    if format == "obj" {
        for k in 0..n * n {
            let [x, y, z] = vertex(k % n, k / n);
            writeln!(w, "v {x} {y} {z}").unwrap();
        }
        for q in 0..quads {
            let [a, b, c, d] = corners(q).map(|v| v + 1);
            writeln!(w, "f {a} {b} {c}\nf {a} {c} {d}").unwrap();
        }
    } else {
        let (faces, ascii) = match format {
            "ply-binary" => (2 * quads, false),
            "ply-ascii" => (2 * quads, true),
            "ply-quads" => (quads, false),
            _ => panic!("unknown format `{format}`"),
        };
        let kind = if ascii {
            "ascii"
        } else {
            "binary_little_endian"
        };
        write!(
            w,
            "ply\nformat {kind} 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
             property float z\nproperty float nx\nproperty float ny\nproperty float nz\n\
             element face {faces}\nproperty list uchar int vertex_indices\nend_header\n",
            n * n
        )
        .unwrap();
        for k in 0..n * n {
            let [x, y, z] = vertex(k % n, k / n);
            if ascii {
                writeln!(w, "{x} {y} {z} 0 0 1").unwrap();
            } else {
                for v in [x, y, z, 0.0, 0.0, 1.0] {
                    w.write_all(&v.to_le_bytes()).unwrap();
                }
            }
        }
        for q in 0..quads {
            let [a, b, c, d] = corners(q);
            let polys: Vec<Vec<u32>> = if format == "ply-quads" {
                vec![vec![a, b, c, d]]
            } else {
                vec![vec![a, b, c], vec![a, c, d]]
            };
            for p in polys {
                if ascii {
                    let ids: Vec<String> = p.iter().map(|v| v.to_string()).collect();
                    writeln!(w, "{} {}", p.len(), ids.join(" ")).unwrap();
                } else {
                    w.write_all(&[p.len() as u8]).unwrap();
                    for v in p {
                        w.write_all(&(v as i32).to_le_bytes()).unwrap();
                    }
                }
            }
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (format, n) = match args.as_slice() {
        [f, n, ..] => (f.as_str(), n.parse::<u32>().expect("N: a whole number")),
        _ => panic!("usage: mesh_parse_peak ply-binary|ply-ascii|ply-quads|obj N [DIR]"),
    };
    let tmp = tempfile::tempdir().unwrap();
    let dir = args.get(2).map_or(tmp.path().to_path_buf(), Into::into);
    let path = dir.join(if format == "obj" {
        "grid.obj"
    } else {
        "grid.ply"
    });
    write_grid(&path, format, n);
    let bytes = std::fs::metadata(&path).unwrap().len();
    let before = [status_kib("VmRSS:"), status_kib("VmSize:")];
    let mesh = xylem::scene::mesh_io::load_mesh(&path).unwrap();
    let peak = [status_kib("VmHWM:"), status_kib("VmPeak:")];
    let [resident, address] = [0, 1].map(|k| peak[k].saturating_sub(before[k]) * 1024);
    let per = |b: u64| b as f64 / bytes as f64;
    println!(
        "{format}: {n}x{n} vertices, {} triangles, file {:.1} MB; peak growth: resident {:.1} MB \
         ({:.2} per file byte), address space {:.1} MB ({:.2} per file byte)",
        mesh.indices.len(),
        bytes as f64 / 1e6,
        resident as f64 / 1e6,
        per(resident),
        address as f64 / 1e6,
        per(address)
    );
}
