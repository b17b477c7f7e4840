// Baking one model: load -> clean -> simplify to every ratio -> measure each level against
// level 0 -> fill the LodChain. Levels as Yu, Liang and Chen: l = round(log2 triangles); their ratios by
// model size unless the config gives them.
#include "preprocess/lod_bake.h"

#include "preprocess/mesh_readers.h"
#include "runtime/regular_file.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <sstream>

#include "preprocess/cluster_simplifier.h"
#include "preprocess/decimater_chain.h"
#include "preprocess/gltf_io.h"
#include "preprocess/material_runs.h"
#include "preprocess/mesh_io.h"
#include "preprocess/qem_simplifier.h"
#include "preprocess/surface_error.h"
#include "runtime/geomorph.h"
#include "runtime/lod_asset.h"

namespace lod {
namespace {

// Bump when anything that changes baked output changes (simplifier, measurement, layout):
// it is part of every cache key.
constexpr uint32_t kBakeFormatVersion = 11;  // 11: level 0 keeps authored normals (NRML flag), the vertex hierarchy TEXCOORD_1, colours and those normals (VHAT layout 2); 10: textures embedded in a GLB or data URI kept (IMGS); 9: vertex colours (COL0) and TEXCOORD_1 (TEX1) through the levels, texCoord per texture (MATL layout 2); 8: normal, occlusion, emissive and metallic-roughness textures (MATL layout 1); 7: materials per level (MATL), material boundaries as seams, uv error in QEM's cost; 6: texture coordinates through the levels (TEX0); 5: morph targets repaired in pairs; 4: morph targets (MRPH);
                                             // 3: surface error samples in mesh order

// Up to these sizes a model gets the reference's cow / bunny ratios (Yu, Liang and Chen).
constexpr size_t kSmallModelTriangles = 20000;
constexpr size_t kMediumModelTriangles = 200000;

// Ritter's bounding sphere: start from a far pair, grow over the stragglers.
Sphere bounding_sphere(const float* p, size_t n) {
  Sphere s;
  if (n == 0) return s;
  auto dist2 = [&](size_t a, const double* c) {
    const double dx = p[3 * a] - c[0], dy = p[3 * a + 1] - c[1], dz = p[3 * a + 2] - c[2];
    return dx * dx + dy * dy + dz * dz;
  };
  auto farthest = [&](const double* from) {
    size_t best = 0;
    double bd = -1;
    for (size_t i = 0; i < n; ++i)
      if (double d = dist2(i, from); d > bd) bd = d, best = i;
    return best;
  };
  const double p0[3] = {p[0], p[1], p[2]};
  const size_t a = farthest(p0);
  const double pa[3] = {p[3 * a], p[3 * a + 1], p[3 * a + 2]};
  const size_t b = farthest(pa);
  double c[3] = {(pa[0] + p[3 * b]) / 2, (pa[1] + p[3 * b + 1]) / 2, (pa[2] + p[3 * b + 2]) / 2};
  double r = std::sqrt(dist2(b, c));
  for (size_t i = 0; i < n; ++i) {
    const double d = std::sqrt(dist2(i, c));
    if (d <= r) continue;
    const double nr = (r + d) / 2, k = (nr - r) / d;
    for (int j = 0; j < 3; ++j) c[j] += (p[3 * i + j] - c[j]) * k;
    r = nr;
  }
  // Float rounding must not leave a vertex outside.
  double max_d = 0;
  for (size_t i = 0; i < n; ++i) max_d = std::max(max_d, std::sqrt(dist2(i, c)));
  for (int j = 0; j < 3; ++j) s.center[j] = float(c[j]);
  s.radius = float(std::max(r, max_d) * (1 + 1e-6));
  return s;
}

// The culled level: no vertices, no triangles. Its error is level 0's bounding diameter (the
// most any drawn point can be away from nothing that a viewer can tell), at least the error
// of the level before, so initial levels cull an object once its diameter projects within the
// pixel threshold. Its ranges start at the ends of the buffers.
LodLevel culled_level(const LodChain& chain) {
  LodLevel l;
  l.first_index = uint32_t(chain.indices.size());
  l.first_vertex = uint32_t(chain.positions.size() / 3);
  l.level = level_of_triangles(0);
  const LodLevel& full = chain.levels.front();
  l.error = std::max(2 * full.bounds.radius, chain.levels.back().error);
  l.error_rms = std::max(2 * full.bounds.radius, chain.levels.back().error_rms);
  l.bounds = full.bounds;
  return l;
}

// What the reader skipped (each naming the element).
void note_import_warnings(const MeshData& mesh, std::vector<std::string>& notes) {
  for (const std::string& w : mesh.warnings) notes.push_back("import: " + w);
}

// Authored normals as level 0 keeps them: unit (OBJ's vn need not be), zero and non-finite ones zero.
void unit_normals_in_place(std::vector<float>& n) {
  for (size_t v = 0; v + 2 < n.size(); v += 3) {
    const double len =
        std::sqrt(double(n[v]) * n[v] + double(n[v + 1]) * n[v + 1] + double(n[v + 2]) * n[v + 2]);
    const bool unit = std::abs(len - 1) <= 0.5 * kTreeNormalTolerance;
    for (int k = 0; k < 3; ++k)
      n[v + size_t(k)] = !std::isfinite(len) || len == 0 ? 0.f
                         : unit                          ? n[v + size_t(k)]
                                                         : float(n[v + size_t(k)] / len);
  }
}

const char* method_name(SimplifyMethod m) {
  switch (m) {
    case SimplifyMethod::qem: return "qem";
    case SimplifyMethod::extreme: return "extreme";
    case SimplifyMethod::automatic: return "auto";
  }
  return "?";
}

// Ratios as given (or defaults), checked; sorted from fine to coarse, 1.0 first, unique. A
// last ratio of 0 (the culled level) is taken off and reported through `culled`.
Status resolve_ratios(const BakeSettings& settings, size_t triangles, const std::string& what,
                      std::vector<float>& out, bool& culled) {
  out = settings.ratios.empty() ? default_ratios(triangles) : settings.ratios;
  culled = out.size() > 1 && out.back() == 0.0f;
  if (culled) out.pop_back();
  for (float r : out)
    if (!(r > 0.0f && r <= 1.0f))
      return Status::error(what + ": LOD ratio " + std::to_string(r) + " is outside (0, 1] (0 only as the last)");
  out.push_back(1.0f);
  std::sort(out.begin(), out.end(), std::greater<float>());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return Status::success();
}

// The vertex attributes the simplifiers carry, interleaved per vertex in this order: uv
// (TEXCOORD_0), uv1 (TEXCOORD_1), RGBA colour, each only when the mesh has it. QEM interpolates
// them along each collapse and weights every one in its cost; the aggressive simplifier averages
// them per cell (only the colours are kept from it: it cannot keep uv seams).
struct AttributeLayout {
  static constexpr size_t kNone = SIZE_MAX;
  size_t uv = kNone, uv1 = kNone, color = kNone;
  size_t count = 0;
};

AttributeLayout attribute_layout(const MeshData& mesh) {
  AttributeLayout a;
  const size_t nv = mesh.vertex_count();
  if (mesh.uvs.size() == 2 * nv) a.uv = a.count, a.count += 2;
  if (mesh.uvs1.size() == 2 * nv) a.uv1 = a.count, a.count += 2;
  if (mesh.colors.size() == 4 * nv) a.color = a.count, a.count += 4;
  return a;
}

std::vector<float> interleave_attributes(const MeshData& mesh, const AttributeLayout& a) {
  const size_t nv = mesh.vertex_count();
  std::vector<float> out(a.count * nv);
  auto put = [&](size_t at, const std::vector<float>& column, size_t per) {
    if (at == AttributeLayout::kNone) return;
    for (size_t v = 0; v < nv; ++v) std::copy_n(&column[per * v], per, &out[a.count * v + at]);
  };
  put(a.uv, mesh.uvs, 2);
  put(a.uv1, mesh.uvs1, 2);
  put(a.color, mesh.colors, 4);
  return out;
}

// One attribute (at `at`, `per` floats) of every vertex of an interleaved array.
std::vector<float> attribute_column(const std::vector<float>& interleaved, const AttributeLayout& a, size_t at, size_t per) {
  const size_t nv = a.count ? interleaved.size() / a.count : 0;
  std::vector<float> out(per * nv);
  for (size_t v = 0; v < nv; ++v) std::copy_n(&interleaved[a.count * v + at], per, &out[per * v]);
  return out;
}

// Levels by lodkit's own simplifiers: level 0 is the cleaned input, then one QEM run makes
// every coarser level (both halves of the mesh as parts; run one after the other here, the
// output is the same as in parallel), or the aggressive simplifier does. With method "auto",
// a QEM level stuck more than 2 % above its target is redone by the aggressive simplifier,
// and said so in the notes.
// With several materials (vertex_material: one per input vertex) the aggressive simplifier runs
// per material; QEM keeps them apart by itself (material boundaries are split: seams, which it
// simplifies only along their length).
void simplify_chain(const MeshData& mesh, const std::vector<int32_t>& vertex_material, const std::vector<float>& ratios,
                    SimplifyMethod method, bool automatic, float uv_weight, const BakeParallelFor& parallel_for,
                    std::vector<ChainLevel>& levels, std::vector<std::vector<uint32_t>>& sources,
                    std::vector<std::string>& notes) {
  const bool per_material = distinct_materials(vertex_material) > 1;
  const AttributeLayout layout = attribute_layout(mesh);
  const std::vector<float> attributes = interleave_attributes(mesh, layout);
  bool clustered = false;
  auto cluster = [&](ChainLevelOut* out, const size_t* targets, size_t count) {
    clustered = true;
    // Only colours survive clustering: without them it carries no attributes (uvs are dropped).
    ClusterOptions options;
    if (layout.color != AttributeLayout::kNone) options.attributes = attributes.data(), options.attribute_count = layout.count;
    if (per_material)
      cluster_simplify_per_material(out, mesh, vertex_material, targets, count, options.attributes,
                                    options.attribute_count);
    else
      cluster_simplify_chain(out, mesh.positions.data(), mesh.vertex_count(), mesh.indices.data(), mesh.indices.size(),
                             targets, count, options);
  };
  const size_t triangles = mesh.triangle_count();
  levels.assign(ratios.size(), ChainLevel{});
  ChainLevel& full = levels[0];
  full.positions = mesh.positions;
  full.indices = mesh.indices;
  if (layout.uv != AttributeLayout::kNone) full.uvs = mesh.uvs;
  if (layout.uv1 != AttributeLayout::kNone) full.uvs1 = mesh.uvs1;
  if (layout.color != AttributeLayout::kNone) full.colors = mesh.colors;
  full.target_triangles = triangles;
  full.normals.resize(mesh.positions.size());
  compute_vertex_normals(full.positions.data(), full.vertex_count(), full.indices.data(), full.indices.size(),
                         full.normals.data());
  // Input vertex each level's vertex descends from (level 0 is the input itself).
  sources.assign(ratios.size(), {});
  sources[0].resize(full.vertex_count());
  for (uint32_t v = 0; v < sources[0].size(); ++v) sources[0][v] = v;
  if (ratios.size() < 2) return;
  std::vector<size_t> targets;
  for (size_t i = 1; i < ratios.size(); ++i) targets.push_back(size_t(std::llround(double(ratios[i]) * double(triangles))));
  std::vector<ChainLevelOut> out(targets.size());
  bool keep_uvs = layout.uv != AttributeLayout::kNone || layout.uv1 != AttributeLayout::kNone;
  if (method == SimplifyMethod::qem) {
    const ParallelFor one_by_one = [](size_t n, const std::function<void(size_t)>& body) {
      for (size_t i = 0; i < n; ++i) body(i);
    };
    // Texture coordinates and colours ride along as attributes: interpolated along each
    // collapse; vertices sharing a position (uv or colour seams) move only along their seam,
    // both copies together, so the texture never tears or smears across a seam.
    QemOptions options;
    if (layout.count)
      options.attributes = attributes.data(), options.attribute_count = layout.count, options.attribute_weight = uv_weight;
    qem_simplify_chain_split(out.data(), mesh.positions.data(), mesh.vertex_count(), mesh.indices.data(),
                             mesh.indices.size(), targets.data(), targets.size(), options,
                             parallel_for ? ParallelFor(parallel_for) : one_by_one);
    for (size_t i = 0; i < out.size(); ++i) {
      if (double(out[i].triangle_count()) <= 1.02 * double(targets[i])) continue;
      std::string note = "ratio " + std::to_string(ratios[i + 1]) + ": QEM stopped at " +
                         std::to_string(out[i].triangle_count()) + " triangles for a target of " +
                         std::to_string(targets[i]) + " (no legal collapse left: topology or locked vertices)";
      if (automatic) {
        cluster(&out[i], &targets[i], 1);
        note += "; the aggressive simplifier made this level (" + std::to_string(out[i].triangle_count()) + ")";
        keep_uvs = false;
      }
      notes.push_back(note);
    }
  } else {
    cluster(out.data(), targets.data(), targets.size());
    keep_uvs = false;
  }
  if (per_material && clustered)
    notes.push_back("the aggressive simplifier clustered each material's triangles on its own grid: where two "
                    "materials meet, their levels may leave hairline gaps");
  if (!keep_uvs && (!full.uvs.empty() || !full.uvs1.empty())) {
    notes.push_back(std::string(full.uvs1.empty() ? "texture coordinates" : "texture coordinates (both sets)") + " of " +
                    mesh.source +
                    " dropped: the aggressive simplifier (vertex clustering) made a level, and it cannot keep uv seams");
    full.uvs.clear();
    full.uvs1.clear();
  }
  for (size_t i = 0; i < out.size(); ++i) {
    ChainLevel& l = levels[i + 1];
    l.positions = std::move(out[i].positions);
    l.indices = std::move(out[i].indices);
    sources[i + 1] = std::move(out[i].source_vertex);
    if (keep_uvs && layout.uv != AttributeLayout::kNone) l.uvs = attribute_column(out[i].attributes, layout, layout.uv, 2);
    if (keep_uvs && layout.uv1 != AttributeLayout::kNone)
      l.uvs1 = attribute_column(out[i].attributes, layout, layout.uv1, 2);
    if (layout.color != AttributeLayout::kNone) l.colors = attribute_column(out[i].attributes, layout, layout.color, 4);
    l.target_triangles = targets[i];
    l.normals.resize(l.positions.size());
    compute_vertex_normals(l.positions.data(), l.vertex_count(), l.indices.data(), l.indices.size(), l.normals.data());
  }
}

// Every level's values of one attribute (`per` floats a vertex: ChainLevel::*column), and how far
// each level's slid: the largest distance of a vertex's value from that of the input vertex it
// descends from (the levels' `sources`): for uvs, in texture units; for colours, in RGBA.
void add_attribute(const std::vector<ChainLevel>& levels, const std::vector<std::vector<uint32_t>>& sources,
                   std::vector<float> ChainLevel::*column, size_t per, std::vector<float>& values,
                   std::vector<float>& errors) {
  const std::vector<float>& input = levels[0].*column;
  for (size_t k = 0; k < levels.size(); ++k) {
    const ChainLevel& l = levels[k];
    const std::vector<float>& mine = l.*column;
    float worst = 0;
    for (size_t v = 0; v < l.vertex_count() && v < sources[k].size(); ++v) {
      const float* from = &input[per * size_t(sources[k][v])];
      const float* at = &mine[per * v];
      if (per == 2) {
        worst = std::max(worst, std::hypot(at[0] - from[0], at[1] - from[1]));
      } else {
        float sum = 0;
        for (size_t c = 0; c < per; ++c) sum += (at[c] - from[c]) * (at[c] - from[c]);
        worst = std::max(worst, std::sqrt(sum));
      }
    }
    values.insert(values.end(), mine.begin(), mine.end());
    errors.push_back(worst);
  }
}

}  // namespace

std::vector<float> default_ratios(size_t triangles) {
  if (triangles <= kSmallModelTriangles) return {1.0f, 0.5f, 0.25f, 0.12f, 0.06f};
  if (triangles <= kMediumModelTriangles) return {1.0f, 0.5f, 0.25f, 0.12f, 0.06f, 0.03f};
  return {1.0f, 0.25f, 0.12f, 0.06f, 0.03f, 0.015f, 0.0075f, 0.0037f, 0.0018f};
}

uint64_t bake_key(const std::filesystem::path& mesh_file, const BakeSettings& settings, Status* status) {
  auto fail = [&](Status s) {
    if (status) *status = std::move(s);
    return uint64_t{0};
  };
  // The file's head is checked against its format first (a FIFO, a device or a sparse file
  // that cannot be a mesh is refused unread), then its bytes are hashed in pieces.
  {
    RegularFile f;
    uint64_t read_bytes = 0;
    if (Status s = detail::open_mesh_file(mesh_file, f, read_bytes); !s) return fail(std::move(s));
  }
  uint64_t content = 0;
  if (Status s = hash_regular_file(mesh_file, content); !s) return fail(std::move(s));
  // A .gltf's geometry (and an OBJ's materials) may live in the files it names: they are part
  // of the content. A missing one adds the hash of no bytes (the load says it is missing);
  // one that is not a regular file is refused by name.
  std::string ext = mesh_file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".gltf" || ext == ".glb" || ext == ".obj")
    for (const auto& file : ext == ".obj" ? obj_external_files(mesh_file) : gltf_external_files(mesh_file)) {
      std::error_code ec;
      if (!std::filesystem::exists(file, ec)) {
        content = hash_bytes(nullptr, 0, content);
        continue;
      }
      uint64_t more = 0;
      if (Status s = hash_regular_file(file, more, content); !s) return fail(std::move(s));
      content = more;
    }
  // Settings as explicit little records, so padding never enters the hash.
  std::vector<uint8_t> s;
  auto put = [&s](const void* p, size_t n) {
    const auto* b = static_cast<const uint8_t*>(p);
    s.insert(s.end(), b, b + n);
  };
  put(&kBakeFormatVersion, sizeof kBakeFormatVersion);
  const uint8_t method = static_cast<uint8_t>(settings.method);
  put(&method, 1);
  put(&settings.extreme_threshold, sizeof settings.extreme_threshold);
  put(&settings.uv_weight, sizeof settings.uv_weight);
  const uint64_t n = settings.ratios.size();
  put(&n, sizeof n);
  for (float r : settings.ratios) put(&r, sizeof r);
  if (status) *status = Status::success();
  return hash_bytes(s.data(), s.size(), content);
}

Status bake_model(const std::filesystem::path& mesh_file, const std::string& name, const BakeSettings& settings,
                  LodChain& out, BakeReport* report_out, const BakeProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  auto say = [&progress](float f, const char* what) {
    if (progress) progress(std::clamp(f, 0.0f, 1.0f), what);
  };
  BakeReport report;
  const std::string what = name.empty() ? mesh_file.string() : name + " (" + mesh_file.string() + ")";

  say(0.0f, "load");
  MeshData mesh;
  Status s = load_mesh(mesh_file, mesh);
  if (!s) return s;
  report.input_triangles = mesh.triangle_count();
  note_import_warnings(mesh, report.notes);

  say(0.04f, "clean");
  report.cleaned = clean_mesh(mesh);
  if (mesh.triangle_count() == 0)
    return Status::error(mesh_file.string() + ": no triangles left after cleaning (all degenerate)");
  // Authored normals are level 0's (and so the vertex hierarchy's) unless cleaning welded copies
  // that differ in normal only (hard edges: one side's normal would shade both); then they are
  // not kept, and said so. Coarser levels' normals always come from their faces.
  const bool authored_normals = !mesh.normals.empty() && report.cleaned.normal_conflicts == 0;
  if (!mesh.normals.empty() && !authored_normals)
    report.notes.push_back(
        "authored normals of " + mesh_file.string() +
        " not kept: " + std::to_string(report.cleaned.normal_conflicts) +
        " welded vertices differ in normal only (hard edges); every level's normals and the "
        "view-dependent mesh's are computed from their faces");

  std::vector<float> ratios;
  bool culled = false;
  s = resolve_ratios(settings, mesh.triangle_count(), what, ratios, culled);
  if (!s) return s;

  SimplifyMethod method = settings.method;
  if (method == SimplifyMethod::automatic)
    method = report.input_triangles > settings.extreme_threshold ? SimplifyMethod::extreme : SimplifyMethod::qem;
  report.method = std::string(method == SimplifyMethod::qem ? "lodkit-qem" : "lodkit-aggressive") + " (" +
                  (settings.method == SimplifyMethod::automatic ? "auto -> " : "") + method_name(method) + ")";
  if (method == SimplifyMethod::extreme)
    report.notes.push_back("method 'extreme': vertex clustering with quadric placement (lodkit aggressive simplifier)");

  say(0.06f, "simplify");
  std::vector<ChainLevel> levels;
  std::vector<std::vector<uint32_t>> sources;
  LodChain chain;
  add_chain_materials(mesh, mesh_file, chain, report.notes);
  std::vector<int32_t> vertex_material = vertex_materials(mesh);
  for (int32_t& m : vertex_material)
    if (m >= int32_t(chain.materials.size())) m = -1;
  simplify_chain(mesh, vertex_material, ratios, method, settings.method == SimplifyMethod::automatic,
                 settings.uv_weight, settings.parallel_for, levels, sources, report.notes);
  if (authored_normals) {
    levels[0].normals = mesh.normals;
    unit_normals_in_place(levels[0].normals);
    chain.authored_normals = true;
  }

  // A level no smaller than the one before it adds nothing: drop it.
  for (size_t i = 1; i < levels.size();) {
    if (levels[i].triangle_count() >= levels[i - 1].triangle_count()) {
      report.notes.push_back("dropped the level for ratio " + std::to_string(ratios[i]) + ": no fewer triangles (" +
                             std::to_string(levels[i].triangle_count()) + ") than the level before");
      levels.erase(levels.begin() + std::ptrdiff_t(i));
      sources.erase(sources.begin() + std::ptrdiff_t(i));
      ratios.erase(ratios.begin() + std::ptrdiff_t(i));
    } else {
      ++i;
    }
  }

  // Each level's triangles grouped by material (before anything reads their order).
  if (!chain.materials.empty())
    for (size_t i = 0; i < levels.size(); ++i)
      group_by_material(levels[i].indices, sources[i], vertex_material, uint32_t(i), chain.submeshes);

  say(0.6f, "measure");
  std::vector<SurfaceError> errors(levels.size());
  if (levels.size() > 1) {
    SurfaceErrorMeter meter;
    const ChainLevel& l0 = levels[0];
    s = meter.set_reference({l0.positions.data(), l0.vertex_count(), l0.indices.data(), l0.indices.size()},
                            SurfaceErrorSettings{}, what);
    if (!s) return s;
    // Levels are measured independently against the same reference, so they may run in parallel.
    std::vector<Status> measured(levels.size());
    std::atomic<size_t> done{0};
    auto measure_level = [&](size_t k) {
      const ChainLevel& l = levels[k + 1];
      measured[k + 1] =
          meter.measure({l.positions.data(), l.vertex_count(), l.indices.data(), l.indices.size()}, errors[k + 1]);
      say(0.6f + 0.38f * float(++done) / float(levels.size() - 1), "measure");
    };
    if (settings.parallel_for) {
      settings.parallel_for(levels.size() - 1, measure_level);
    } else {
      for (size_t k = 0; k + 1 < levels.size(); ++k) measure_level(k);
    }
    for (size_t i = 1; i < levels.size(); ++i)
      if (!measured[i]) return measured[i];
  }
  // A coarser level never reports less error than a finer one: selection relies on it.
  for (size_t i = 1; i < errors.size(); ++i) {
    errors[i].max = std::max(errors[i].max, errors[i - 1].max);
    errors[i].rms = std::max(errors[i].rms, errors[i - 1].rms);
  }

  chain.name = name;
  Status key_status;
  chain.source_hash = bake_key(mesh_file, settings, &key_status);
  if (!key_status) return key_status;
  size_t total_vertices = 0, total_indices = 0;
  for (const ChainLevel& l : levels) total_vertices += l.vertex_count(), total_indices += l.indices.size();
  if (total_vertices > UINT32_MAX || total_indices > UINT32_MAX)
    return Status::error(what + ": the chain has more than 2^32 vertices or indices");
  chain.positions.reserve(3 * total_vertices);
  chain.normals.reserve(3 * total_vertices);
  chain.indices.reserve(total_indices);
  for (size_t i = 0; i < levels.size(); ++i) {
    const ChainLevel& l = levels[i];
    LodLevel level;
    level.first_index = uint32_t(chain.indices.size());
    level.index_count = uint32_t(l.indices.size());
    level.first_vertex = uint32_t(chain.positions.size() / 3);
    level.vertex_count = uint32_t(l.vertex_count());
    level.level = level_of_triangles(l.triangle_count());
    level.error = errors[i].max;
    level.error_rms = errors[i].rms;
    level.bounds = bounding_sphere(l.positions.data(), l.vertex_count());
    chain.positions.insert(chain.positions.end(), l.positions.begin(), l.positions.end());
    chain.normals.insert(chain.normals.end(), l.normals.begin(), l.normals.end());
    chain.indices.insert(chain.indices.end(), l.indices.begin(), l.indices.end());
    chain.levels.push_back(level);
  }
  if (!levels[0].uvs.empty()) add_attribute(levels, sources, &ChainLevel::uvs, 2, chain.uvs, chain.uv_errors);
  if (!levels[0].uvs1.empty()) add_attribute(levels, sources, &ChainLevel::uvs1, 2, chain.uvs1, chain.uv1_errors);
  if (!levels[0].colors.empty()) add_attribute(levels, sources, &ChainLevel::colors, 4, chain.colors, chain.color_errors);
  // Morph targets of each level into the next, from the simplifier's vertex mapping; levels
  // are independent, so they may run in parallel.
  if (levels.size() > 1) {
    say(0.98f, "morph targets");
    const auto morph_start = std::chrono::steady_clock::now();
    chain.morph_targets.resize(morph_target_count(chain));
    std::vector<size_t> misses(levels.size() - 1, 0);
    auto targets_of = [&](size_t k) {
      const ChainLevel& fine = levels[k];
      const ChainLevel& coarse = levels[k + 1];
      const LodLevel& lv = chain.levels[k];
      misses[k] = level_morph_targets_by_collapse(
          std::span(chain.morph_targets.data() + lv.first_vertex, lv.vertex_count), fine.positions, fine.indices,
          sources[k], coarse.positions, coarse.indices, sources[k + 1]);
    };
    if (settings.parallel_for) {
      settings.parallel_for(levels.size() - 1, targets_of);
    } else {
      for (size_t k = 0; k + 1 < levels.size(); ++k) targets_of(k);
    }
    report.morph_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - morph_start).count();
    for (size_t k = 0; k < misses.size(); ++k)
      if (misses[k] > 0)
        report.notes.push_back("morph targets: " + std::to_string(misses[k]) + " of level " + std::to_string(k) +
                               "'s " + std::to_string(levels[k].triangle_count()) +
                               " triangles land on no level " + std::to_string(k + 1) +
                               " triangle when fully morphed (a blend there is approximate)");
  }
  if (culled) {
    chain.levels.push_back(culled_level(chain));
    if (!chain.uvs.empty()) chain.uv_errors.push_back(chain.uv_errors.back());
    if (!chain.uvs1.empty()) chain.uv1_errors.push_back(chain.uv1_errors.back());
    if (!chain.colors.empty()) chain.color_errors.push_back(chain.color_errors.back());
  }
  std::string problem;
  if (!validate_chain(chain, &problem)) return Status::error(what + ": baked chain is invalid: " + problem);

  say(1.0f, "done");
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out = std::move(chain);
  if (report_out) *report_out = std::move(report);
  return Status::success();
}

}  // namespace lod
