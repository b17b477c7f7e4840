// `lod export --3dtiles DIR FILE.hlod` end to end: the tileset passes the 3D Tiles 1.1
// JSON schemas (ajv, when ../shared holds them) and the structural checks of
// validate_3dtiles.js, every GLB the Khronos validator with 0 errors; tiles follow the tree and
// its measured errors; a non-empty folder is refused (or, with --force, only an earlier export
// replaced); a corrupted .hlod writes nothing; files are named by node, never by model name.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "preprocess/mesh_io.h"
#include "run_cli.h"
#include "test_support.h"
#include "textured_fixture.h"

namespace {

namespace fs = std::filesystem;
using lod::test::run_lod;

fs::path schema_dir() { return fs::path(LOD_SHARED_MESHES).parent_path() / "schemas" / "3d-tiles-1.1"; }

// validate_3dtiles.js on `tileset` ("-" for schemas: structure and glTF only). The node tools
// missing is a failure, not a skip: scripts/run-tests.sh installs them before any test runs.
lod::test::CliResult run_checker(const fs::path& tileset, const std::string& schemas, bool glbs = true) {
  lod::test::CliResult r;
  const fs::path tools = LOD_NODE_TOOLS;
  for (const char* pkg : {"gltf-validator", "ajv", "ajv-formats"})
    if (!fs::exists(LOD_NODE_EXECUTABLE) || !fs::exists(tools / "node_modules" / pkg / "package.json")) {
      r.out = std::string("npm ") + pkg + " is not installed in " + tools.string() + ": run scripts/install-node-tools.sh";
      return r;
    }
  const std::string cmd = std::string(LOD_NODE_EXECUTABLE) + " " + LOD_SOURCE_DIR "/tests/integration/validate_3dtiles.js '" +
                          tools.string() + "' '" + schemas + "' '" + tileset.string() + "'" + (glbs ? "" : " --no-gltf");
  return lod::test::run_shell(cmd);
}

// The unit sphere stretched to 3 along y and moved to z = 5, so that y-up and z-up differ.
std::string tall_ball_off() {
  std::istringstream in(lod::test::sphere_off(60, 80));
  std::ostringstream out;
  std::string line;
  std::getline(in, line);
  out << line << "\n";
  int vertices = 0, faces = 0, edges = 0;
  in >> vertices >> faces >> edges;
  out << vertices << " " << faces << " 0\n";
  for (int v = 0; v < vertices; ++v) {
    double x, y, z;
    in >> x >> y >> z;
    out << x << " " << 3 * y << " " << z + 5 << "\n";
  }
  std::getline(in, line);
  while (std::getline(in, line)) out << line << "\n";
  return out.str();
}

// A tall ball's .hlod (a few dozen nodes, three levels deep).
fs::path bake_ball_hlod(const fs::path& dir, const std::string& stem = "ball") {
  const fs::path mesh = dir / (stem + ".off");
  lod::test::write_text(mesh, tall_ball_off());
  const auto r = run_lod("bake '" + mesh.string() + "' -o '" + (dir / "hlod").string() + "' --hlod --min-verts 300 --quiet");
  EXPECT_EQ(r.code, 0) << r.out;
  return dir / "hlod" / (stem + ".hlod");
}

nlohmann::json read_json(const fs::path& file) {
  std::ifstream f(file);
  return nlohmann::json::parse(f);
}

void write_json(const fs::path& file, const nlohmann::json& j) { lod::test::write_text(file, j.dump()); }

// Every tile of the tileset, depth first, with its parent's index (-1 at the root).
void flatten(const nlohmann::json& tile, int parent, std::vector<std::pair<const nlohmann::json*, int>>& out) {
  const int me = int(out.size());
  out.push_back({&tile, parent});
  if (tile.contains("children"))
    for (const auto& c : tile["children"]) flatten(c, me, out);
}

bool hidden_leftovers(const fs::path& parent) {
  for (const auto& e : fs::directory_iterator(parent))
    if (e.path().filename().string().find(".partial-") != std::string::npos ||
        e.path().filename().string().find(".old-") != std::string::npos)
      return true;
  return false;
}

TEST(Tiles3dExport, EveryTileFollowsTheTreeAndEveryGlbPassesTheValidator) {
  const fs::path dir = lod::test::temp_dir("tiles3d-valid");
  const fs::path hlod = bake_ball_hlod(dir);
  const auto r = run_lod("export --3dtiles '" + (dir / "tiles").string() + "' '" + hlod.string() + "' --json");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto report = nlohmann::json::parse(r.out);
  const auto inspect = run_lod("inspect '" + hlod.string() + "' --json");
  ASSERT_EQ(inspect.code, 0) << inspect.out;
  const auto tree = nlohmann::json::parse(inspect.out);

  // One tile per layer with triangles and per boundary patch; their errors are the layers'.
  size_t want_tiles = 0;
  std::multiset<double> want_errors;
  for (const auto& n : tree["nodes"]) {
    for (const auto& l : n["layers"]) {
      ++want_tiles;
      want_errors.insert(l["error"].get<double>());
    }
    if (n["boundary_triangles"].get<uint32_t>() > 0) ++want_tiles, want_errors.insert(0.0);
  }
  EXPECT_EQ(report["nodes"], tree["nodes"].size());
  EXPECT_EQ(report["tiles"].get<size_t>(), want_tiles);
  EXPECT_EQ(report["glb_files"].get<size_t>(), want_tiles);

  const auto tileset = read_json(dir / "tiles" / "tileset.json");
  EXPECT_EQ(tileset["asset"]["version"], "1.1");
  EXPECT_EQ(tileset["root"]["refine"], "REPLACE");
  std::vector<std::pair<const nlohmann::json*, int>> tiles;
  flatten(tileset["root"], -1, tiles);
  ASSERT_EQ(tiles.size(), want_tiles);
  std::multiset<double> got_errors;
  for (const auto& [t, parent] : tiles) {
    got_errors.insert((*t)["geometricError"].get<float>());
    EXPECT_TRUE((*t)["content"]["uri"].get<std::string>().starts_with("tiles/"));
  }
  std::multiset<double> want_float;
  for (double e : want_errors) want_float.insert(float(e));
  EXPECT_EQ(got_errors, want_float);
  // The root tile is the root node's coarsest layer.
  const auto& root_layers = tree["nodes"][0]["layers"];
  EXPECT_FLOAT_EQ(tileset["root"]["geometricError"].get<float>(), root_layers.back()["error"].get<float>());
  EXPECT_GE(tileset["geometricError"].get<double>(), tileset["root"]["geometricError"].get<double>());

  // z-up: the ball's height (glTF y, 3) is the box's z axis; glTF z = 5 is tileset y = -5.
  const auto& box = tileset["root"]["boundingVolume"]["box"];
  EXPECT_NEAR(box[0].get<double>(), 0.0, 0.01);
  EXPECT_NEAR(box[1].get<double>(), -5.0, 0.01);
  EXPECT_NEAR(box[2].get<double>(), 0.0, 0.01);
  EXPECT_NEAR(box[3].get<double>(), 1.0, 0.01);
  EXPECT_NEAR(box[7].get<double>(), 1.0, 0.01);
  EXPECT_NEAR(box[11].get<double>(), 3.0, 0.01);

  const auto v = run_checker(dir / "tiles" / "tileset.json", "-");
  EXPECT_EQ(v.code, 0) << v.out;
  EXPECT_NE(v.out.find("structure errors 0 gltf errors 0 tiles " + std::to_string(want_tiles)), std::string::npos) << v.out;
  EXPECT_FALSE(hidden_leftovers(dir));
}

TEST(Tiles3dExport, TilesetPassesThe3dTilesSchemas) {
  if (!fs::exists(schema_dir() / "tileset.schema.json"))
    GTEST_SKIP() << "the 3D Tiles 1.1 schemas are not at " << schema_dir() << " (../shared absent)";
  const fs::path dir = lod::test::temp_dir("tiles3d-schema");
  const fs::path hlod = bake_ball_hlod(dir);
  ASSERT_EQ(run_lod("export --3dtiles '" + (dir / "tiles").string() + "' '" + hlod.string() + "'").code, 0);
  const auto v = run_checker(dir / "tiles" / "tileset.json", schema_dir().string());
  EXPECT_EQ(v.code, 0) << v.out;
  EXPECT_NE(v.out.find("schema errors 0 structure errors 0 gltf errors 0"), std::string::npos) << v.out;
}

// The checks must fail on broken tilesets, or the tests above prove nothing.
TEST(Tiles3dExport, TheCheckerReportsBrokenTilesets) {
  const fs::path dir = lod::test::temp_dir("tiles3d-broken");
  const fs::path hlod = bake_ball_hlod(dir);
  ASSERT_EQ(run_lod("export --3dtiles '" + (dir / "good").string() + "' '" + hlod.string() + "'").code, 0);
  const auto good = read_json(dir / "good" / "tileset.json");
  struct Case {
    const char* name;
    std::function<void(nlohmann::json&)> edit;
    const char* says;
  };
  const std::vector<Case> cases = {
      {"version", [](nlohmann::json& t) { t["asset"]["version"] = "1.0"; }, "asset.version"},
      {"error", [](nlohmann::json& t) { t["root"]["children"][0]["geometricError"] = 1e6; }, "above its parent's"},
      {"box", [](nlohmann::json& t) { t["root"]["children"][0]["boundingVolume"]["box"][3] = 1e3; }, "box outside its parent's"},
      // Content shrunk to a point: the GLB's positions are outside it.
      {"content", [](nlohmann::json& t) {
         auto& b = t["root"]["content"]["boundingVolume"]["box"];
         for (int k = 3; k < 12; ++k) b[size_t(k)] = 0.0;
       }, "outside its content box"},
      // Left in glTF's y-up frame: centre (x, y, z), half sizes along x, y, z.
      {"y-up", [](nlohmann::json& t) {
         for (auto* v : {&t["root"]["boundingVolume"]["box"], &t["root"]["content"]["boundingVolume"]["box"]}) {
           auto& b = *v;
           const double cy = b[1], cz = b[2], hy = b[7], hz = b[11];
           b[1] = cz, b[2] = -cy, b[7] = hz, b[11] = hy;
         }
       }, "outside its content box"},
      {"escape", [](nlohmann::json& t) { t["root"]["content"]["uri"] = "../tiles-outside.glb"; }, "inside the tileset"},
      {"missing", [](nlohmann::json& t) { t["root"]["content"]["uri"] = "tiles/none.glb"; }, "does not exist"},
  };
  for (const Case& c : cases) {
    const fs::path to = dir / c.name;
    fs::copy(dir / "good", to, fs::copy_options::recursive);
    nlohmann::json t = good;
    c.edit(t);
    write_json(to / "tileset.json", t);
    const auto v = run_checker(to / "tileset.json", "-", false);
    EXPECT_EQ(v.code, 1) << c.name << ": " << v.out;
    EXPECT_NE(v.out.find(c.says), std::string::npos) << c.name << ": " << v.out;
  }
  // A GLB the glTF validator refuses.
  const fs::path to = dir / "glb";
  fs::copy(dir / "good", to, fs::copy_options::recursive);
  const std::string first = good["root"]["content"]["uri"];
  auto bytes = lod::test::read_bytes(to / first);
  bytes.resize(bytes.size() - 8);
  lod::test::write_bytes(to / first, bytes);
  const auto v = run_checker(to / "tileset.json", "-");
  EXPECT_EQ(v.code, 1) << v.out;
  EXPECT_EQ(v.out.find("gltf errors 0"), std::string::npos) << v.out;
  if (fs::exists(schema_dir() / "tileset.schema.json")) {  // and the schemas, a required key dropped
    nlohmann::json t = good;
    t["root"].erase("geometricError");
    write_json(dir / "good" / "tileset.json", t);
    const auto s = run_checker(dir / "good" / "tileset.json", schema_dir().string(), false);
    EXPECT_EQ(s.code, 1) << s.out;
    EXPECT_NE(s.out.find("required property 'geometricError'"), std::string::npos) << s.out;
  }
}

TEST(Tiles3dExport, RefusesANonEmptyFolderAndForceReplacesOnlyAnEarlierExport) {
  const fs::path dir = lod::test::temp_dir("tiles3d-force");
  const fs::path hlod = bake_ball_hlod(dir);
  const std::string args = "' '" + hlod.string() + "'";
  fs::create_directories(dir / "empty");
  EXPECT_EQ(run_lod("export --3dtiles '" + (dir / "empty").string() + args).code, 0) << "an empty folder is written";
  EXPECT_TRUE(fs::exists(dir / "empty" / "tileset.json"));

  fs::create_directories(dir / "mine");
  lod::test::write_text(dir / "mine" / "notes.txt", "keep me");
  auto r = run_lod("export --3dtiles '" + (dir / "mine").string() + args);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("is not empty"), std::string::npos) << r.out;
  r = run_lod("export --3dtiles '" + (dir / "mine").string() + args + " --force");
  EXPECT_NE(r.code, 0) << "a folder without a tileset.json is never replaced";
  EXPECT_NE(r.out.find("holds no tileset.json"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir / "mine" / "notes.txt"));

  ASSERT_EQ(run_lod("export --3dtiles '" + (dir / "out").string() + args).code, 0);
  ASSERT_TRUE(fs::is_directory(dir / "out" / "tiles"));
  lod::test::write_text(dir / "out" / "tiles" / "stale.glb", "from before");
  r = run_lod("export --3dtiles '" + (dir / "out").string() + args);
  EXPECT_NE(r.code, 0) << "an earlier export is not replaced without --force";
  r = run_lod("export --3dtiles '" + (dir / "out").string() + args + " --force");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_FALSE(fs::exists(dir / "out" / "tiles" / "stale.glb")) << "replaced whole, nothing stale kept";
  EXPECT_EQ(run_checker(dir / "out" / "tileset.json", "-").code, 0);
  lod::test::write_text(dir / "file", "x");
  EXPECT_NE(run_lod("export --3dtiles '" + (dir / "file").string() + args).code, 0);
  EXPECT_FALSE(hidden_leftovers(dir));
}

TEST(Tiles3dExport, ACorruptedHlodWritesNothing) {
  const fs::path dir = lod::test::temp_dir("tiles3d-corrupt");
  const fs::path hlod = bake_ball_hlod(dir);
  auto bytes = lod::test::read_bytes(hlod);
  bytes[bytes.size() - 20] ^= 0x5a;  // inside the last node's payload: every earlier GLB was written
  lod::test::write_bytes(dir / "bad.hlod", bytes);
  auto r = run_lod("export --3dtiles '" + (dir / "tiles").string() + "' '" + (dir / "bad.hlod").string() + "'");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("bad.hlod"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("checksum"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "tiles"));
  EXPECT_FALSE(hidden_leftovers(dir));
  // Not an .hlod at all, and the head cut short.
  lod::test::write_text(dir / "x.hlod", "not an hlod file at all, no");
  r = run_lod("export --3dtiles '" + (dir / "tiles").string() + "' '" + (dir / "x.hlod").string() + "'");
  EXPECT_NE(r.code, 0);
  bytes.resize(200);
  lod::test::write_bytes(dir / "short.hlod", bytes);
  r = run_lod("export --3dtiles '" + (dir / "tiles").string() + "' '" + (dir / "short.hlod").string() + "'");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("short.hlod"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "tiles"));
  EXPECT_FALSE(hidden_leftovers(dir));
}

TEST(Tiles3dExport, FilesAreNamedByNodeNeverByTheModelName) {
  const fs::path dir = lod::test::temp_dir("tiles3d-names");
  const fs::path hlod = bake_ball_hlod(dir, "..;$(x) ba\\ll");
  ASSERT_TRUE(fs::exists(hlod));
  ASSERT_EQ(run_lod("export --3dtiles '" + (dir / "tiles").string() + "' '" + hlod.string() + "'").code, 0);
  const std::regex tile_name(R"([0-9]+-([0-9]|boundary)\.glb)");
  size_t files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir / "tiles")) {
    const fs::path rel = fs::relative(e.path(), dir / "tiles");
    if (e.is_directory()) {
      EXPECT_EQ(rel, "tiles");
      continue;
    }
    ++files;
    if (rel == "tileset.json") continue;
    EXPECT_EQ(rel.parent_path(), "tiles") << rel;
    EXPECT_TRUE(std::regex_match(rel.filename().string(), tile_name)) << rel;
  }
  EXPECT_GT(files, 10u);
  EXPECT_EQ(read_json(dir / "tiles" / "tileset.json")["asset"]["extras"]["model"], "..;$(x) ba\\ll");
}

}  // namespace

namespace {

// Every GLB of a tileset read back (the glTF importer): uvs, materials by name, triangles by run.
struct TiledGlb {
  fs::path file;
  lod::MeshData mesh;
};
std::vector<TiledGlb> read_tiles(const fs::path& tiles) {
  std::vector<TiledGlb> out;
  for (const auto& e : fs::directory_iterator(tiles / "tiles")) {
    TiledGlb t{e.path(), {}};
    const lod::Status st = lod::load_mesh(e.path(), t.mesh);
    EXPECT_TRUE(st) << st.message;
    out.push_back(std::move(t));
  }
  return out;
}

// The two-material sphere (textured cap above the equator, uv v in [0, 0.5]; untextured base
// below, v in [0.5, 1]) -> lod bake --hlod -> lod export --3dtiles: every GLB has TEXCOORD_0 and
// its runs' materials, the cap's texture embedded, every uv in its chart, and passes the
// validator with 0 errors; lod inspect lists the materials.
TEST(Tiles3dExport, TexturedModelKeepsItsUvsMaterialsAndTextureInEveryTile) {
  const fs::path dir = lod::test::temp_dir("tiles3d-textured");
  const fs::path gltf = lod::test::write_two_material_gltf(dir / "src", "globe", 48, 96);
  ASSERT_FALSE(gltf.empty());
  auto r = run_lod("bake '" + gltf.string() + "' -o '" + (dir / "hlod").string() + "' --hlod --min-verts 300 --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path hlod = dir / "hlod" / "globe.hlod";
  const auto inspect = run_lod("inspect '" + hlod.string() + "' --json");
  ASSERT_EQ(inspect.code, 0) << inspect.out;
  const auto tree = nlohmann::json::parse(inspect.out);
  EXPECT_TRUE(tree["texcoords"].get<bool>());
  ASSERT_EQ(tree["materials"].size(), 2u);
  EXPECT_EQ(tree["materials"][0]["name"], "cap");
  EXPECT_EQ(tree["materials"][0]["textures"]["base colour"], "globe-image0.png");
  EXPECT_EQ(tree["materials"][1]["name"], "base");
  const auto shown = run_lod("inspect '" + hlod.string() + "'");
  EXPECT_NE(shown.out.find("materials: 2"), std::string::npos) << shown.out;
  EXPECT_NE(shown.out.find("0 'cap'"), std::string::npos) << shown.out;
  EXPECT_NE(shown.out.find("base colour texture globe-image0.png"), std::string::npos) << shown.out;

  r = run_lod("export --3dtiles '" + (dir / "tiles").string() + "' '" + hlod.string() + "' --json");
  ASSERT_EQ(r.code, 0) << r.out;
  const std::vector<TiledGlb> glbs = read_tiles(dir / "tiles");
  ASSERT_GT(glbs.size(), 8u);
  size_t textured = 0;
  for (const TiledGlb& g : glbs) {
    const lod::MeshData& m = g.mesh;
    ASSERT_EQ(m.uvs.size(), 2 * m.vertex_count()) << g.file;
    ASSERT_FALSE(m.materials.empty()) << g.file;
    for (const lod::Submesh& s : m.submeshes) {
      ASSERT_GE(s.material, 0) << g.file;
      const lod::MeshMaterial& mat = m.materials[size_t(s.material)];
      const bool cap = mat.name == "cap";
      EXPECT_TRUE(cap || mat.name == "base") << mat.name;
      if (cap) {
        EXPECT_TRUE(mat.base_color_texture_embedded) << g.file;
        ++textured;
      }
      for (uint32_t t = s.first_triangle; t < s.first_triangle + s.triangle_count; ++t)
        for (int c = 0; c < 3; ++c) {
          const float* uv = &m.uvs[2 * size_t(m.indices[3 * size_t(t) + size_t(c)])];
          ASSERT_GE(uv[0], -1e-4f) << g.file;
          ASSERT_LE(uv[0], 1 + 1e-4f) << g.file;
          if (cap) {
            ASSERT_LE(uv[1], 0.5f + 1e-4f) << g.file << " triangle " << t;
          } else {
            ASSERT_GE(uv[1], 0.5f - 1e-4f) << g.file << " triangle " << t;
          }
        }
    }
  }
  EXPECT_GT(textured, 0u);
  const auto v = run_checker(dir / "tiles" / "tileset.json", "-");
  EXPECT_EQ(v.code, 0) << v.out;
  EXPECT_NE(v.out.find("structure errors 0 gltf errors 0"), std::string::npos) << v.out;
  if (fs::exists(schema_dir())) {
    const auto schemas = run_checker(dir / "tiles" / "tileset.json", schema_dir().string(), false);
    EXPECT_EQ(schemas.code, 0) << schemas.out;
  }

  // --shared-images: the texture written once under textures/, every GLB naming it by a
  // relative URI, still valid (the checker resolves it), and the tileset smaller.
  r = run_lod("export --3dtiles '" + (dir / "shared").string() + "' '" + hlod.string() + "' --shared-images --json");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto shared_report = nlohmann::json::parse(r.out);
  EXPECT_EQ(shared_report["shared_images"], 1);
  size_t images = 0;
  for (const auto& e : fs::directory_iterator(dir / "shared" / "textures")) images += e.is_regular_file();
  EXPECT_EQ(images, 1u);
  EXPECT_LT(shared_report["bytes"].get<uint64_t>(), nlohmann::json::parse(run_lod("export --3dtiles '" +
            (dir / "again").string() + "' '" + hlod.string() + "' --json").out)["bytes"].get<uint64_t>());
  size_t referring = 0;
  for (const TiledGlb& g : read_tiles(dir / "shared"))
    for (const lod::MeshMaterial& m : g.mesh.materials)
      if (m.name == "cap") {
        EXPECT_FALSE(m.base_color_texture_embedded) << g.file;
        EXPECT_EQ(m.base_color_texture, "../textures/image0.png") << g.file;
        ++referring;
      }
  EXPECT_GT(referring, 0u);
  const auto sv = run_checker(dir / "shared" / "tileset.json", fs::exists(schema_dir()) ? schema_dir().string() : "-");
  EXPECT_EQ(sv.code, 0) << sv.out;
  EXPECT_NE(sv.out.find("structure errors 0 gltf errors 0"), std::string::npos) << sv.out;
}

// The coloured sphere (north red, green following the latitude; south blue at alpha 0.5; a
// colour seam on the equator; TEXCOORD_1 with an occlusion texture reading it) -> lod bake --hlod
// -> lod export --3dtiles: every GLB has COLOR_0 and TEXCOORD_1 (and TEXCOORD_0), each vertex
// its half's colour, the occlusion texture on texCoord 1, and the validator and the schemas
// report 0 errors.
TEST(Tiles3dExport, ColouredModelWritesColor0AndTexcoord1InEveryTile) {
  const fs::path dir = lod::test::temp_dir("tiles3d-coloured");
  const fs::path gltf = lod::test::write_coloured_gltf(dir / "src", "painted", 48, 96);
  ASSERT_FALSE(gltf.empty());
  auto r = run_lod("bake '" + gltf.string() + "' -o '" + (dir / "hlod").string() + "' --hlod --min-verts 300 --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path hlod = dir / "hlod" / "painted.hlod";
  r = run_lod("export --3dtiles '" + (dir / "tiles").string() + "' '" + hlod.string() + "' --json");
  ASSERT_EQ(r.code, 0) << r.out;
  const std::vector<TiledGlb> glbs = read_tiles(dir / "tiles");
  ASSERT_GT(glbs.size(), 8u);
  size_t red = 0, blue = 0;
  for (const TiledGlb& g : glbs) {
    const lod::MeshData& m = g.mesh;
    ASSERT_EQ(m.uvs.size(), 2 * m.vertex_count()) << g.file;
    ASSERT_EQ(m.uvs1.size(), 2 * m.vertex_count()) << g.file << ": TEXCOORD_1";
    ASSERT_EQ(m.colors.size(), 4 * m.vertex_count()) << g.file << ": COLOR_0";
    ASSERT_EQ(m.materials.size(), 1u) << g.file;
    EXPECT_FALSE(m.materials[0].occlusion_texture.empty()) << g.file;
    EXPECT_EQ(m.materials[0].tex_coords[3], 1) << g.file << ": occlusion reads TEXCOORD_1";
    for (size_t v = 0; v < m.vertex_count(); ++v) {
      const float* c = &m.colors[4 * v];
      const float y = m.positions[3 * v + 1];
      if (c[0] > 0.5f) {
        ++red;
        ASSERT_GE(y, -0.02f) << g.file;
        ASSERT_NEAR(c[3], 1.0f, 1e-5f) << g.file;
      } else {
        ++blue;
        ASSERT_LE(y, 0.02f) << g.file;
        ASSERT_NEAR(c[2], 1.0f, 1e-5f) << g.file;
        ASSERT_NEAR(c[3], 0.5f, 1e-5f) << g.file;
      }
      ASSERT_GE(m.uvs1[2 * v], 0.25f - 1e-4f) << g.file;
      ASSERT_LE(m.uvs1[2 * v], 0.75f + 1e-4f) << g.file;
    }
  }
  EXPECT_GT(red, 0u);
  EXPECT_GT(blue, 0u);
  const auto v = run_checker(dir / "tiles" / "tileset.json", "-");
  EXPECT_EQ(v.code, 0) << v.out;
  EXPECT_NE(v.out.find("structure errors 0 gltf errors 0"), std::string::npos) << v.out;
  if (fs::exists(schema_dir())) {
    const auto schemas = run_checker(dir / "tiles" / "tileset.json", schema_dir().string(), false);
    EXPECT_EQ(schemas.code, 0) << schemas.out;
  }
}

// ../shared's spot with its texture (a .mtl naming it) as an HLOD and a tileset: the figures
// docs/performance.md can quote, and every GLB valid with the texture embedded.
TEST(Tiles3dExport, SpotHlodExportsWithItsTexture) {
  LOD_REQUIRE_SHARED_MESH(spot, "spot.obj");
  const fs::path dir = lod::test::temp_dir("tiles3d-spot");
  const std::vector<uint8_t> obj = lod::test::read_bytes(spot);
  std::string text = "mtllib spot.mtl\nusemtl spot\n";
  text.append(obj.begin(), obj.end());
  lod::test::write_text(dir / "spot.obj", text);
  lod::test::write_text(dir / "spot.mtl", "newmtl spot\nKd 1 1 1\nmap_Kd spot_texture.png\n");
  fs::copy_file(spot.parent_path() / "spot_texture.png", dir / "spot_texture.png");
  auto r = run_lod("bake '" + (dir / "spot.obj").string() + "' -o '" + (dir / "hlod").string() + "' --hlod --min-verts 500 --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path hlod = dir / "hlod" / "spot.hlod";
  const auto inspect = run_lod("inspect '" + hlod.string() + "' --json");
  ASSERT_EQ(inspect.code, 0) << inspect.out;
  const auto tree = nlohmann::json::parse(inspect.out);
  ASSERT_EQ(tree["materials"].size(), 1u);
  EXPECT_EQ(tree["materials"][0]["textures"]["base colour"], "spot_texture.png");
  double uv_error = 0;
  for (const auto& n : tree["nodes"])
    for (const auto& l : n["layers"]) uv_error = std::max(uv_error, l["uv_error"].get<double>());
  r = run_lod("export --3dtiles '" + (dir / "tiles").string() + "' '" + hlod.string() + "' --json");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto report = nlohmann::json::parse(r.out);
  std::printf("spot hlod: %zu nodes, %zu bytes; largest layer uv error %.4g; tileset %zu GLBs, %.2f MB\n",
              tree["nodes"].size(), tree["bytes"].get<size_t>(), uv_error, report["glb_files"].get<size_t>(),
              double(report["bytes"].get<uint64_t>()) / 1e6);
  for (const TiledGlb& g : read_tiles(dir / "tiles")) {
    EXPECT_EQ(g.mesh.uvs.size(), 2 * g.mesh.vertex_count()) << g.file;
    ASSERT_EQ(g.mesh.materials.size(), 1u) << g.file;
    EXPECT_TRUE(g.mesh.materials[0].base_color_texture_embedded) << g.file;
  }
  const auto v = run_checker(dir / "tiles" / "tileset.json", fs::exists(schema_dir()) ? schema_dir().string() : "-");
  EXPECT_EQ(v.code, 0) << v.out;
}

}  // namespace
