// Textured models simplified side by side with meshoptimizer's gltfpack:
// `gltfpack -si R -noq` (Debian's gltfpack, run as a process; -noq keeps float attributes so
// that only the simplification differs) and lodkit's bake (QEM, uvs as attributes, seams
// simplified along their length) at the triangle count gltfpack reached for each R in 50 %,
// 25 %, 12.5 %, 6.25 %.
// Both are measured by the same code against the same original: geometric error
// (preprocess/surface_error: Embree closest points, symmetric, RMS and max, in % of the
// bounding-box diagonal) and texture-coordinate error (preprocess/uv_error, in texels of the
// base colour texture).
//
//   bench_gltf_peers [--csv FILE] [--samples N] [--no-spot]
//
// Models: a bumpy uv-mapped torus made here (seams where u and v wrap; uv error in 1/1024 of
// the uv range, i.e. texels of a 1024 x 1024 texture), and spot from ../shared/data/meshes
// when present (texels of spot_texture.png's size); both written as OBJ + MTL with a base
// colour texture and converted to GLB by gltfpack at run time (a textured material is what
// makes gltfpack keep TEXCOORD_0). Nothing is committed. Writes FILE (default bench_gltf_peers.csv) and
// an .svg next to it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "preprocess/lod_bake.h"
#include "preprocess/mesh_io.h"
#include "preprocess/surface_error.h"
#include "preprocess/uv_error.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;

struct Model {
  std::string name;
  fs::path glb;
  double texture_width = 1024, texture_height = 1024;
};

struct Row {
  std::string model, method;
  double target = 0;  // R asked of gltfpack
  size_t input = 0, triangles = 0;
  double geo_rms = 0, geo_max = 0;  // % of the diagonal
  double uv_rms = 0, uv_mean = 0, uv_max = 0;  // texels
};

bool run(const std::string& cmd) {
  const int rc = std::system((cmd + " > /dev/null 2>&1").c_str());
  if (rc != 0) std::fprintf(stderr, "bench_gltf_peers: failed (%d): %s\n", rc, cmd.c_str());
  return rc == 0;
}

// A 1 x 1 PNG: the torus's texture file (gltfpack keeps TEXCOORD_0 only for a textured
// material, and the importer wants the image to exist; it is never decoded).
const unsigned char kTinyPng[] = {
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00, 0x00, 0x01,
    0x00, 0x00, 0x00, 0x01, 0x08, 0x02, 0x00, 0x00, 0x00, 0x90, 0x77, 0x53, 0xde, 0x00, 0x00, 0x00, 0x0c, 0x49, 0x44, 0x41,
    0x54, 0x08, 0xd7, 0x63, 0xf8, 0xcf, 0xc0, 0x00, 0x00, 0x03, 0x01, 0x01, 0x00, 0x18, 0xdd, 0x8d, 0xb0, 0x00, 0x00, 0x00,
    0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};

// OBJ + MTL with a base colour texture, for gltfpack to convert (textures keep uvs alive).
void write_mtl(const fs::path& dir, const std::string& name, const std::string& texture) {
  std::ofstream(dir / (name + ".mtl")) << "newmtl " << name << "\nKd 1 1 1\nmap_Kd " << texture << "\n";
}

// A (rings x segments) bumpy torus, uv-mapped once around each way: the u and v seams are
// columns of vertices with the same positions and uvs 0 and 1.
bool write_torus_obj(const fs::path& dir, int rings, int segments) {
  std::ofstream out(dir / "torus.obj");
  out << "mtllib torus.mtl\nusemtl torus\n";
  const double R = 1.0, r = 0.35;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      // The last row and column are the first again (i % rings, j % segments), so the seam's
      // copies share their positions bit for bit: a seam, not two borders a rounding apart.
      const double a = 2 * std::numbers::pi * (i % rings) / rings, b = 2 * std::numbers::pi * (j % segments) / segments;
      const double rr = r * (1 + 0.08 * std::sin(5 * a) * std::cos(3 * b));  // curvature to trade against the texture
      out << "v " << (R + rr * std::cos(b)) * std::cos(a) << ' ' << rr * std::sin(b) << ' '
          << (R + rr * std::cos(b)) * std::sin(a) << "\nvt " << double(i) / rings << ' ' << double(j) / segments << '\n';
    }
  const auto at = [&](int i, int j) { return i * (segments + 1) + j + 1; };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const int a = at(i, j), b = at(i, j + 1), c = at(i + 1, j + 1), d = at(i + 1, j);
      out << "f " << a << '/' << a << ' ' << b << '/' << b << ' ' << c << '/' << c << "\nf " << a << '/' << a << ' ' << c << '/'
          << c << ' ' << d << '/' << d << '\n';
    }
  write_mtl(dir, "torus", "torus.png");
  std::ofstream(dir / "torus.png", std::ios::binary).write(reinterpret_cast<const char*>(kTinyPng), sizeof kTinyPng);
  return bool(out);
}

// spot.obj (no mtllib of its own) with a material naming its texture, both copied here.
bool write_spot_obj(const fs::path& shared, const fs::path& dir) {
  std::ifstream in(shared / "spot.obj");
  std::ofstream out(dir / "spot.obj");
  out << "mtllib spot.mtl\nusemtl spot\n" << in.rdbuf();
  write_mtl(dir, "spot", "spot_texture.png");
  std::error_code ec;
  fs::copy_file(shared / "spot_texture.png", dir / "spot_texture.png", fs::copy_options::overwrite_existing, ec);
  return bool(out) && !ec;
}

// Width and height from a PNG's IHDR chunk (bytes 16..23, big-endian); false if not a PNG.
bool png_size(const fs::path& file, double& w, double& h) {
  std::ifstream f(file, std::ios::binary);
  unsigned char b[24] = {};
  if (!f.read(reinterpret_cast<char*>(b), 24) || b[1] != 'P' || b[2] != 'N' || b[3] != 'G') return false;
  auto be = [&](int o) { return double(uint32_t(b[o]) << 24 | uint32_t(b[o + 1]) << 16 | uint32_t(b[o + 2]) << 8 | b[o + 3]); };
  w = be(16), h = be(20);
  return w > 0 && h > 0;
}

double diagonal(const std::vector<float>& p) {
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (size_t i = 0; i < p.size(); ++i) lo[i % 3] = std::min(lo[i % 3], double(p[i])), hi[i % 3] = std::max(hi[i % 3], double(p[i]));
  return std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

// Both measures of one level against the original.
struct Meters {
  lod::SurfaceErrorMeter geo;
  lod::UvErrorMeter uv;
  double diag = 1;
};

bool measure(Meters& m, const float* pos, const float* uvs, size_t vertices, const uint32_t* idx, size_t indices, Row& r) {
  lod::SurfaceError g;
  lod::UvError u;
  const lod::Status a = m.geo.measure({pos, vertices, idx, indices}, g);
  const lod::Status b = m.uv.measure({pos, uvs, vertices, idx, indices}, u);
  if (!a || !b) {
    std::fprintf(stderr, "bench_gltf_peers: %s\n", (!a ? a : b).message.c_str());
    return false;
  }
  r.triangles = indices / 3;
  r.geo_rms = 100 * g.rms / m.diag, r.geo_max = 100 * g.max / m.diag;
  r.uv_rms = u.rms, r.uv_mean = u.mean, r.uv_max = u.max;
  return true;
}

bool run_model(const Model& model, const fs::path& work, size_t samples, std::vector<Row>& rows) {
  lod::MeshData original;
  if (lod::Status s = lod::load_mesh(model.glb, original); !s) {
    std::fprintf(stderr, "bench_gltf_peers: %s\n", s.message.c_str());
    return false;
  }
  if (original.uvs.empty()) {
    std::fprintf(stderr, "bench_gltf_peers: %s has no texture coordinates\n", model.glb.c_str());
    return false;
  }
  Meters m;
  m.diag = diagonal(original.positions);
  lod::SurfaceErrorSettings gs;
  gs.surface_samples = samples;
  lod::UvErrorSettings us;
  us.surface_samples = samples;
  us.texture_width = model.texture_width, us.texture_height = model.texture_height;
  const lod::TriangleMeshView ref{original.positions.data(), original.vertex_count(), original.indices.data(),
                                  original.indices.size()};
  if (!m.geo.set_reference(ref, gs, model.name).ok ||
      !m.uv.set_reference({original.positions.data(), original.uvs.data(), original.vertex_count(), original.indices.data(),
                           original.indices.size()},
                          us, model.name).ok)
    return false;
  const size_t input = original.triangle_count();

  // gltfpack first: its counts are the targets ours is asked for.
  const double targets[] = {0.5, 0.25, 0.125, 0.0625};
  std::vector<float> ratios = {1.0f};
  std::vector<Row> theirs;
  for (double R : targets) {
    char name[64];
    std::snprintf(name, sizeof name, "%s-gltfpack-%g.glb", model.name.c_str(), R);
    const fs::path out = work / name;
    char cmd[1024];
    std::snprintf(cmd, sizeof cmd, "gltfpack -i '%s' -o '%s' -si %g -noq", model.glb.c_str(), out.c_str(), R);
    if (!run(cmd)) return false;
    lod::MeshData level;
    if (lod::Status s = lod::load_mesh(out, level); !s || level.uvs.empty()) {
      std::fprintf(stderr, "bench_gltf_peers: %s\n", s.ok ? "gltfpack output has no uvs" : s.message.c_str());
      return false;
    }
    Row r{model.name, "gltfpack", R, input};
    if (!measure(m, level.positions.data(), level.uvs.data(), level.vertex_count(), level.indices.data(),
                 level.indices.size(), r))
      return false;
    theirs.push_back(r);
    const float ratio = float(double(r.triangles) / double(input));
    if (ratio < ratios.back()) ratios.push_back(ratio);
  }

  // Ours at those counts: one bake of the whole chain from the same GLB.
  lod::BakeSettings settings;
  settings.method = lod::SimplifyMethod::qem;
  settings.ratios = ratios;
  lod::LodChain chain;
  lod::BakeReport report;
  if (lod::Status s = lod::bake_model(model.glb, model.name, settings, chain, &report, nullptr); !s) {
    std::fprintf(stderr, "bench_gltf_peers: %s\n", s.message.c_str());
    return false;
  }
  if (chain.uvs.empty()) {
    std::fprintf(stderr, "bench_gltf_peers: the bake of %s kept no uvs\n", model.name.c_str());
    return false;
  }
  for (const Row& t : theirs) {
    // The level whose count is nearest gltfpack's.
    size_t best = 1;
    for (size_t k = 1; k < chain.levels.size(); ++k)
      if (std::abs(double(chain.levels[k].triangles()) - double(t.triangles)) <
          std::abs(double(chain.levels[best].triangles()) - double(t.triangles)))
        best = k;
    const lod::LodLevel& l = chain.levels[best];
    Row r{model.name, "lodkit-qem", t.target, input};
    if (!measure(m, chain.positions.data() + 3 * size_t(l.first_vertex), chain.uvs.data() + 2 * size_t(l.first_vertex),
                 l.vertex_count, chain.indices.data() + l.first_index, l.index_count, r))
      return false;
    rows.push_back(t);
    rows.push_back(r);
    std::printf("%-8s R %-7g gltfpack %7zu tris: geo rms %.4f%% max %.3f%%, uv rms %.3f max %.2f texels | lodkit %7zu tris: "
                "geo rms %.4f%% max %.3f%%, uv rms %.3f max %.2f texels | ratio geo rms %.2f uv rms %.2f\n",
                model.name.c_str(), t.target, t.triangles, t.geo_rms, t.geo_max, t.uv_rms, t.uv_max, r.triangles, r.geo_rms,
                r.geo_max, r.uv_rms, r.uv_max, r.geo_rms / std::max(t.geo_rms, 1e-12), r.uv_rms / std::max(t.uv_rms, 1e-12));
    std::fflush(stdout);
  }
  return true;
}

void write_csv(const std::string& path, const std::vector<Row>& rows) {
  std::ofstream out(path);
  out << "model,method,target_ratio,input_triangles,triangles,geo_rms_pct_diag,geo_max_pct_diag,uv_rms_texels,uv_mean_texels,"
         "uv_max_texels\n";
  for (const Row& r : rows)
    out << r.model << ',' << r.method << ',' << r.target << ',' << r.input << ',' << r.triangles << ',' << r.geo_rms << ','
        << r.geo_max << ',' << r.uv_rms << ',' << r.uv_mean << ',' << r.uv_max << '\n';
}

// Two panels per model: geometric RMS (% of the diagonal) and uv RMS (texels), both log,
// against the triangle ratio (log), one line per method.
void write_plot(const std::string& path, const std::vector<Row>& rows) {
  const char* methods[] = {"lodkit-qem", "gltfpack"};
  const char* colours[] = {"#1f77b4", "#d62728"};
  std::vector<std::string> models;
  for (const Row& r : rows)
    if (std::find(models.begin(), models.end(), r.model) == models.end()) models.push_back(r.model);
  const double pw = 380, ph = 200, left = 60, top = 40, gap = 90;
  std::ofstream out(path);
  out << "<svg xmlns='http://www.w3.org/2000/svg' width='" << 2 * (left + pw) + 40 << "' height='"
      << top + (ph + gap) * double(models.size()) << "' font-family='sans-serif' font-size='11'>\n"
      << "<rect width='100%' height='100%' fill='white'/>\n";
  for (size_t k = 0; k < 2; ++k)
    out << "<text x='" << left + 120 * double(k) << "' y='16' fill='" << colours[k] << "'>" << methods[k] << "</text>\n";
  for (size_t m = 0; m < models.size(); ++m)
    for (int panel = 0; panel < 2; ++panel) {
      auto value = [&](const Row& r) { return panel == 0 ? r.geo_rms : r.uv_rms; };
      double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
      for (const Row& r : rows) {
        if (r.model != models[m] || value(r) <= 0 || r.triangles == 0) continue;
        const double x = std::log10(double(r.triangles) / double(r.input)), y = std::log10(value(r));
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
      if (x1 <= x0) x1 = x0 + 1;
      if (y1 <= y0) y1 = y0 + 1;
      const double ox = left + double(panel) * (pw + left + 20), oy = top + double(m) * (ph + gap);
      auto px = [&](const Row& r) { return ox + (std::log10(double(r.triangles) / double(r.input)) - x0) / (x1 - x0) * pw; };
      auto py = [&](const Row& r) { return oy + (y1 - std::log10(value(r))) / (y1 - y0) * ph; };
      out << "<text x='" << ox << "' y='" << oy - 6 << "'>" << models[m]
          << (panel == 0 ? ": geometric RMS (% of diagonal, log)" : ": uv RMS (texels, log)") << " vs triangles kept (log)</text>\n";
      out << "<rect x='" << ox << "' y='" << oy << "' width='" << pw << "' height='" << ph << "' fill='none' stroke='#999'/>\n";
      for (size_t k = 0; k < 2; ++k) {
        std::string pts;
        for (const Row& r : rows)
          if (r.model == models[m] && r.method == methods[k] && value(r) > 0) {
            pts += std::to_string(px(r)) + "," + std::to_string(py(r)) + " ";
            out << "<circle cx='" << px(r) << "' cy='" << py(r) << "' r='2.5' fill='" << colours[k] << "'/>\n";
          }
        out << "<polyline points='" << pts << "' fill='none' stroke='" << colours[k] << "'/>\n";
      }
      for (const Row& r : rows)
        if (r.model == models[m] && r.method == methods[1]) {
          char label[32];
          std::snprintf(label, sizeof label, "%.1f%%", 100.0 * double(r.triangles) / double(r.input));
          out << "<text x='" << px(r) - 12 << "' y='" << oy + ph + 14 << "'>" << label << "</text>\n";
        }
      char lo[32], hi[32];
      std::snprintf(lo, sizeof lo, "%.2g", std::pow(10.0, y0));
      std::snprintf(hi, sizeof hi, "%.2g", std::pow(10.0, y1));
      out << "<text x='" << ox - 44 << "' y='" << oy + 10 << "'>" << hi << "</text><text x='" << ox - 44 << "' y='" << oy + ph
          << "'>" << lo << "</text>\n";
    }
  out << "</svg>\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::string csv = "bench_gltf_peers.csv";
  size_t samples = 50000;
  bool spot = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--csv" && i + 1 < argc) csv = argv[++i];
    else if (a == "--samples" && i + 1 < argc) samples = std::stoul(argv[++i]);
    else if (a == "--no-spot") spot = false;
    else {
      std::fprintf(stderr, "usage: bench_gltf_peers [--csv FILE] [--samples N] [--no-spot]\n");
      return 2;
    }
  }
  if (std::system("gltfpack -h > /dev/null 2>&1") != 0 && std::system("command -v gltfpack > /dev/null") != 0) {
    std::fprintf(stderr, "bench_gltf_peers: gltfpack is not installed (Debian package gltfpack)\n");
    return 1;
  }
  const fs::path work = fs::path(LOD_BINARY_DIR) / "bench-data" / "gltf-peers";
  std::error_code ec;
  fs::create_directories(work, ec);
  std::vector<Model> models;
  if (write_torus_obj(work, 256, 96) &&
      run("gltfpack -i '" + (work / "torus.obj").string() + "' -o '" + (work / "torus.glb").string() + "' -noq"))
    models.push_back({"torus", work / "torus.glb"});
  const fs::path shared = lod::test::shared_meshes();
  if (spot && !shared.empty() && fs::exists(shared / "spot.obj")) {
    Model m{"spot", work / "spot.glb"};
    if (!png_size(shared / "spot_texture.png", m.texture_width, m.texture_height))
      std::printf("spot_texture.png not readable: texels of a 1024 x 1024 texture\n");
    if (write_spot_obj(shared, work) &&
        run("gltfpack -i '" + (work / "spot.obj").string() + "' -o '" + m.glb.string() + "' -noq"))
      models.push_back(m);
  } else if (spot) {
    std::printf("spot.obj not in ../shared/data/meshes: the generated torus only\n");
  }
  std::vector<Row> rows;
  for (const Model& m : models)
    if (!run_model(m, work, samples, rows)) return 1;
  write_csv(csv, rows);
  const std::string svg = csv.size() > 4 && csv.ends_with(".csv") ? csv.substr(0, csv.size() - 4) + ".svg" : csv + ".svg";
  write_plot(svg, rows);
  std::printf("wrote %s and %s\n", csv.c_str(), svg.c_str());
  return 0;
}
