// Converts the npm package `bunny` (1.0.1) to OBJ with area-weighted vertex normals.
// Usage: node scenes/meshes/bunny_to_obj.js path/to/bunny/index.js > scenes/meshes/bunny.obj
const b = require(require("path").resolve(process.argv[2]));
const P = b.positions, C = b.cells;
const N = P.map(() => [0, 0, 0]);
for (const [a, c1, c2] of C) {
  const u = [0, 1, 2].map(i => P[c1][i] - P[a][i]), v = [0, 1, 2].map(i => P[c2][i] - P[a][i]);
  const n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
  for (const k of [a, c1, c2]) for (let i = 0; i < 3; i++) N[k][i] += n[i];
}
const f = x => x.toFixed(6);
let s = "# The Stanford bunny (Stanford 3D Scanning Repository, Turk and Levoy 1994), as shipped by the\n" +
  "# npm package `bunny` 1.0.1 (Mikola Lysenko; licence: Public Domain), converted unchanged to OBJ\n" +
  `# (${P.length} vertices, ${C.length} triangles, y up, units as shipped: 9.65 high) with\n` +
  "# area-weighted vertex normals added. Source and conversion: scenes/meshes/README.md.\n";
for (const p of P) s += `v ${p.map(f).join(" ")}\n`;
for (const n of N) { const l = Math.hypot(...n) || 1; s += `vn ${n.map(x => f(x / l)).join(" ")}\n`; }
for (const c of C) s += `f ${c.map(i => `${i + 1}//${i + 1}`).join(" ")}\n`;
process.stdout.write(s);
