// Checks a 3D Tiles 1.1 tileset:
//   node validate_3dtiles.js NODE_TOOLS SCHEMA_DIR|- TILESET_JSON [--no-gltf]
//   1. the JSON schemas (SCHEMA_DIR = the specification's schema folder; "-" skips this part),
//      through ajv (draft 2020-12) + ajv-formats;
//   2. what the schemas cannot say: asset.version "1.1", refine REPLACE at the root, every
//      child's geometricError <= its parent's, the tileset's >= the root's, every child's box
//      inside its parent's and every content box inside its tile's, content URIs relative and
//      inside the tileset's folder, each file named once and existing, every GLB's POSITION
//      min/max (turned from glTF y-up to 3D Tiles z-up) inside its content box, no file of the
//      folder left unnamed;
//   3. every GLB through the Khronos glTF validator (unless --no-gltf).
// Prints "schema errors S structure errors T gltf errors G tiles N contents C" and each
// problem; exits 1 when any count is not 0.
'use strict';
const fs = require('fs');
const path = require('path');

const [toolsDir, schemaDir, tilesetFile, option] = process.argv.slice(2);
const checkGltf = option !== '--no-gltf';
const modules = path.join(toolsDir, 'node_modules');
const problems = [];
let schemaErrors = 0, structureErrors = 0, gltfErrors = 0;
const structure = (msg) => { structureErrors += 1; problems.push(`structure: ${msg}`); };

function checkSchema(tileset) {
  const Ajv2020 = require(path.join(modules, 'ajv/dist/2020')).default;
  const addFormats = require(path.join(modules, 'ajv-formats')).default;
  const ajv = new Ajv2020({ strict: false, allErrors: true });
  addFormats(ajv);
  ajv.addFormat('iri-reference', true);  // not in ajv-formats; only tileset.schemaUri uses it
  // The schemas' own $ids are bare file names while their $refs are relative paths across
  // folders: each is registered under its path instead, so every $ref resolves.
  const base = 'https://schemas.invalid/3d-tiles/';
  const walk = (dir) => fs.readdirSync(dir, { withFileTypes: true }).flatMap((e) =>
    e.isDirectory() ? walk(path.join(dir, e.name)) : e.name.endsWith('.schema.json') ? [path.join(dir, e.name)] : []);
  for (const file of walk(schemaDir)) {
    const schema = JSON.parse(fs.readFileSync(file, 'utf8'));
    schema.$id = base + path.relative(schemaDir, file).split(path.sep).join('/');
    ajv.addSchema(schema);
  }
  const validate = ajv.getSchema(base + 'tileset.schema.json');
  if (!validate(tileset)) {
    for (const e of validate.errors) problems.push(`schema: ${e.instancePath || '/'} ${e.message}`);
    schemaErrors += validate.errors.length;
  }
}

// A box as centre + three half axes; its 8 corners; whether a point is inside another box.
const boxOf = (b) => ({ c: b.slice(0, 3), axes: [b.slice(3, 6), b.slice(6, 9), b.slice(9, 12)] });
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
function corners(box) {
  const out = [];
  for (let i = 0; i < 8; ++i) {
    const p = box.c.slice();
    for (let k = 0; k < 3; ++k) {
      const s = (i >> k) & 1 ? 1 : -1;
      for (let d = 0; d < 3; ++d) p[d] += s * box.axes[k][d];
    }
    out.push(p);
  }
  return out;
}
// Axes are taken as orthogonal (as 3D Tiles boxes are in practice); a zero axis makes the box
// flat, so what is left of the point after the other axes' parts must be nothing.
function inside(p, box) {
  const rel = [p[0] - box.c[0], p[1] - box.c[1], p[2] - box.c[2]];
  const scale = Math.max(1e-12, ...box.axes.map((a) => Math.sqrt(dot(a, a))), Math.sqrt(dot(rel, rel)));
  const rest = rel.slice();
  for (const a of box.axes) {
    const len2 = dot(a, a);
    if (len2 === 0) continue;
    const t = dot(rel, a) / len2;
    if (Math.abs(t) > 1 + 1e-9) return false;
    for (let d = 0; d < 3; ++d) rest[d] -= t * a[d];
  }
  return Math.sqrt(dot(rest, rest)) <= 1e-9 * scale;
}
const boxInside = (inner, outer) => corners(inner).every((p) => inside(p, outer));

// POSITION min/max of a GLB's meshes, in glTF coordinates.
// The images a GLB names by URI (a shared texture), as files resolved against its folder.
function glbImageFiles(bytes, glb) {
  const json = JSON.parse(bytes.toString('utf8', 20, 20 + bytes.readUInt32LE(12)));
  return (json.images || []).filter((i) => i.uri !== undefined).map((i) => i.uri);
}

function glbPositionBounds(bytes) {
  const u32 = (o) => bytes.readUInt32LE(o);
  if (bytes.length < 20 || bytes.toString('latin1', 0, 4) !== 'glTF') throw new Error('not a GLB');
  const json = JSON.parse(bytes.toString('utf8', 20, 20 + u32(12)));
  const out = [];
  for (const mesh of json.meshes || [])
    for (const prim of mesh.primitives || []) {
      const a = json.accessors[prim.attributes.POSITION];
      if (!a || !a.min || !a.max) throw new Error('POSITION without min/max');
      out.push([a.min, a.max]);
    }
  return out;
}

function checkStructure(tileset, root) {
  if (!tileset.asset || tileset.asset.version !== '1.1') structure(`asset.version is ${JSON.stringify(tileset.asset && tileset.asset.version)}, not "1.1"`);
  if (!tileset.root) return structure('no root tile');
  if (tileset.root.refine !== 'REPLACE') structure(`root refine is ${JSON.stringify(tileset.root.refine)}, not "REPLACE"`);
  if (!(tileset.geometricError >= tileset.root.geometricError)) structure('tileset geometricError below the root\'s');
  const named = new Map();
  const images = new Set();  // files the GLBs share by URI
  let tiles = 0;
  const visit = (tile, where, parent) => {
    tiles += 1;
    const bv = tile.boundingVolume && tile.boundingVolume.box;
    if (!bv || bv.length !== 12) return structure(`${where}: no 12-number boundingVolume.box`);
    if (!bv.every(Number.isFinite)) structure(`${where}: non-finite box`);
    const box = boxOf(bv);
    if (!(tile.geometricError >= 0)) structure(`${where}: geometricError ${tile.geometricError}`);
    if (parent) {
      if (tile.geometricError > parent.tile.geometricError) structure(`${where}: geometricError ${tile.geometricError} above its parent's ${parent.tile.geometricError}`);
      if (!boxInside(box, parent.box)) structure(`${where}: box outside its parent's`);
    }
    if (tile.content) {
      const uri = tile.content.uri;
      const file = path.resolve(root, decodeURIComponent(uri || ''));
      if (!uri || /^[a-z][a-z0-9+.-]*:/i.test(uri) || uri.startsWith('/') || !file.startsWith(root + path.sep)) {
        structure(`${where}: content uri ${JSON.stringify(uri)} is not a relative path inside the tileset`);
      } else if (named.has(file)) {
        structure(`${where}: ${uri} already named by ${named.get(file)}`);
      } else if (!fs.existsSync(file)) {
        structure(`${where}: ${uri} does not exist`);
      } else {
        named.set(file, where);
        // Images a GLB shares by URI: relative, inside the tileset, existing; named by the GLB.
        try {
          for (const u of glbImageFiles(fs.readFileSync(file), file)) {
            const img = path.resolve(path.dirname(file), decodeURIComponent(u));
            if (/^[a-z][a-z0-9+.-]*:/i.test(u) || u.startsWith('/') || !img.startsWith(root + path.sep)) structure(`${where}: ${uri} names image ${JSON.stringify(u)} outside the tileset`);
            else if (!fs.existsSync(img)) structure(`${where}: ${uri} names image ${u}, which does not exist`);
            else images.add(img);
          }
        } catch (e) {
          structure(`${where}: ${uri}: ${e.message}`);
        }
        const cb = tile.content.boundingVolume && tile.content.boundingVolume.box;
        const contentBox = cb ? boxOf(cb) : box;
        if (cb && !boxInside(contentBox, box)) structure(`${where}: content box outside the tile's`);
        try {
          for (const [lo, hi] of glbPositionBounds(fs.readFileSync(file))) {
            // glTF y-up -> 3D Tiles z-up: (x, y, z) -> (x, -z, y).
            const zUp = { c: [(lo[0] + hi[0]) / 2, -(lo[2] + hi[2]) / 2, (lo[1] + hi[1]) / 2],
              axes: [[(hi[0] - lo[0]) / 2, 0, 0], [0, (hi[2] - lo[2]) / 2, 0], [0, 0, (hi[1] - lo[1]) / 2]] };
            if (!boxInside(zUp, contentBox)) structure(`${where}: ${uri}'s positions lie outside its content box`);
          }
        } catch (e) {
          structure(`${where}: ${uri}: ${e.message}`);
        }
      }
    }
    (tile.children || []).forEach((c, i) => visit(c, `${where}/children/${i}`, { tile, box }));
  };
  visit(tileset.root, '/root', null);
  const walk = (dir) => fs.readdirSync(dir, { withFileTypes: true }).flatMap((e) =>
    e.isDirectory() ? walk(path.join(dir, e.name)) : [path.join(dir, e.name)]);
  for (const f of walk(root))
    if (f !== path.resolve(tilesetFile) && !named.has(f) && !images.has(f)) structure(`${path.relative(root, f)} is in the folder but no tile names it`);
  return { tiles, contents: [...named.keys()] };
}

(async () => {
  let tileset;
  try {
    tileset = JSON.parse(fs.readFileSync(tilesetFile, 'utf8'));
  } catch (e) {
    console.log(`${tilesetFile}: cannot be read: ${e.message}`);
    process.exit(1);
  }
  const root = path.dirname(path.resolve(tilesetFile));
  if (schemaDir !== '-') checkSchema(tileset);
  const { tiles, contents } = checkStructure(tileset, root);
  const validator = require(path.join(modules, 'gltf-validator'));
  for (const file of checkGltf ? contents : []) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      uri: path.basename(file),
      externalResourceFunction: (uri) =>
        new Promise((resolve, reject) => {
          fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
            err ? reject(err.toString()) : resolve(new Uint8Array(data)));
        }),
    });
    gltfErrors += report.issues.numErrors;
    for (const m of report.issues.messages)
      if (m.severity === 0) problems.push(`gltf: ${path.relative(root, file)} ${m.code} ${m.pointer || ''}: ${m.message}`);
  }
  console.log(`${tilesetFile}: schema errors ${schemaErrors} structure errors ${structureErrors} gltf errors ${gltfErrors} tiles ${tiles} contents ${contents.length}${schemaDir === '-' ? ' (schemas not checked)' : ''}${checkGltf ? '' : ' (GLBs not validated)'}`);
  for (const p of problems.slice(0, 50)) console.log(`  ${p}`);
  process.exit(schemaErrors + structureErrors + gltfErrors > 0 ? 1 : 0);
})();
