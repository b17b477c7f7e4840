// libFuzzer target for the HLOD bake's cleaned-mesh cache entry (.hmesh, jobs/hlod_mesh_cache:
// positions, indices, uvs, submeshes, materials in MATL layout, images in IMGS layout), built by
// scripts/fuzz.sh. The reader takes a cache folder and a source hash, so each input is written
// to a private folder under the name of the hash it carries, then read as a rerun would.
//
// Seeds: no committed binaries (the format's version moves); scripts/fuzz.sh runs this binary
// with LOD_FUZZ_WRITE_SEEDS=DIR first, and it writes its seeds there through the real writer
// (store_hlod_mesh) and exits.
//
// The custom mutator keeps the trailing checksum valid (a checksum is not a defence) and, three
// times in four, mutates one section of a well-formed entry (indices, submeshes, materials or
// images, resized at will; positions or uvs in place) and rewrites its count to match, so the
// fuzzer gets past the size check into the index, submesh, material and image checks; the
// fourth time it mutates the raw bytes, counts included.
//
// Checks beyond the sanitizers: a refusal says why, naming the entry, and leaves the outputs
// untouched; an accepted entry holds what the bake relies on (indices below the vertex count,
// finite positions and uvs, uvs for every vertex or none, submeshes in order inside the
// triangles naming a stored material, every "embedded:<k>" naming a stored image of its
// type), and stored again by the writer it reads back the same. The in-place reader a node's
// ranks share (view_hlod_mesh) must agree: checked, it accepts exactly what load_hlod_mesh
// accepts, with the same arrays bit for bit; unchecked, an accepted entry views the same.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "jobs/hlod_mesh_cache.h"
#include "runtime/embedded_image.h"
#include "runtime/lod_asset.h"  // hash_bytes

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t max_size);

namespace {

constexpr size_t kFixed = 72;  // the entry's fixed head (jobs/hlod_mesh_cache.cpp)
constexpr uint32_t kFlagUvs = 1;

std::filesystem::path g_dir;     // where each input is written
std::filesystem::path g_redir;   // where an accepted one is stored again

uint32_t u32_at(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}
uint64_t u64_at(const uint8_t* p) {
  uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}
void put_u64(uint8_t* p, uint64_t v) { std::memcpy(p, &v, 8); }

void fix_checksum(uint8_t* data, size_t size) {
  if (size >= kFixed + 8) put_u64(data + size - 8, lod::hash_bytes(data, size - 8));
}

void fail(const std::string& what) {
  std::fprintf(stderr, "%s\n", what.c_str());
  std::abort();
}

// ---- seeds -----------------------------------------------------------------------------------

// A 1x1 RGBA PNG, complete; the reader checks the signature only, the rest is for the fuzzer.
const std::vector<uint8_t> kPng = {
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00,
    0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x06, 0x00, 0x00, 0x00, 0x1f, 0x15, 0xc4, 0x89, 0x00, 0x00, 0x00,
    0x0d, 0x49, 0x44, 0x41, 0x54, 0x78, 0xda, 0x63, 0x64, 0x60, 0xf8, 0x5f, 0x0f, 0x00, 0x02, 0x87, 0x01, 0x80,
    0xeb, 0x47, 0xba, 0x92, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
// A JPEG's start (SOI, APP0 JFIF head, EOI): the signature is what the reader checks.
const std::vector<uint8_t> kJpeg = {0xff, 0xd8, 0xff, 0xe0, 0x00, 0x10, 'J',  'F',  'I',  'F', 0x00,
                                    0x01, 0x01, 0x00, 0x00, 0x01, 0x00, 0x01, 0x00, 0x00, 0xff, 0xd9};

// An n x n grid of vertices in the z = 0 plane, two triangles a cell, uvs when asked.
lod::MeshData grid(uint32_t n, bool uvs) {
  lod::MeshData m;
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      m.positions.insert(m.positions.end(), {float(x), float(y), 0.25f * float((x * y) % 3)});
      if (uvs) m.uvs.insert(m.uvs.end(), {float(x) / float(n - 1), float(y) / float(n - 1)});
    }
  for (uint32_t y = 0; y + 1 < n; ++y)
    for (uint32_t x = 0; x + 1 < n; ++x) {
      const uint32_t a = y * n + x, b = a + 1, c = a + n, d = c + 1;
      m.indices.insert(m.indices.end(), {a, b, d, a, d, c});
    }
  return m;
}

void write_seeds(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  struct Seed {
    uint64_t hash;
    lod::MeshData mesh;
    lod::HlodSurfaces surfaces;
  };
  std::vector<Seed> seeds;
  seeds.push_back({1, grid(5, false), {}});  // geometry only
  {
    Seed s{2, grid(6, true), {}};  // uvs, runs over three materials, a texture base, two images
    const uint32_t triangles = uint32_t(s.mesh.triangle_count());
    s.mesh.submeshes = {{0, triangles / 3, 0}, {triangles / 3, triangles / 3, -1}, {2 * (triangles / 3), triangles - 2 * (triangles / 3), 2}};
    s.surfaces.materials.resize(3);
    s.surfaces.materials[0].name = "stone";
    s.surfaces.materials[0].base_color_texture = "textures/stone%20wall.png";
    s.surfaces.materials[0].normal_texture = "embedded:1";
    s.surfaces.materials[1].name = "glass";
    s.surfaces.materials[1].alpha_mode = lod::AlphaMode::blend;
    s.surfaces.materials[1].base_color[3] = 0.4f;
    s.surfaces.materials[1].double_sided = true;
    s.surfaces.materials[2].name = "leaves";
    s.surfaces.materials[2].alpha_mode = lod::AlphaMode::mask;
    s.surfaces.materials[2].base_color_texture = "embedded:0";
    s.surfaces.materials[2].emissive_texture = "embedded:0";
    s.surfaces.materials[2].emissive[1] = 0.5f;
    s.surfaces.texture_base = "/models/ruin";
    s.surfaces.images = {{lod::ImageType::png, kPng}, {lod::ImageType::jpeg, kJpeg}};
    seeds.push_back(std::move(s));
  }
  {
    Seed s{3, grid(3, true), {}};  // materials without images, a run on the default material
    s.mesh.submeshes = {{0, 8, -1}};
    s.surfaces.materials.resize(1);
    s.surfaces.materials[0].metallic = 0;
    s.surfaces.materials[0].roughness = 0.5f;
    seeds.push_back(std::move(s));
  }
  seeds.push_back({4, lod::MeshData{}, {}});  // empty
  for (const Seed& s : seeds) {
    if (lod::Status st = lod::store_hlod_mesh(dir, s.hash, s.mesh, 7 * s.mesh.triangle_count() + 1, s.surfaces); !st)
      fail("seed: " + st.message);
    lod::MeshData back;
    uint64_t input = 0;
    std::string why;
    if (lod::load_hlod_mesh(dir, s.hash, "seed", back, input, &why) != lod::CacheLookup::found)
      fail("a seed is not accepted: " + why);
  }
  std::printf("[hmesh] %zu seeds written to %s\n", seeds.size(), dir.c_str());
}

// ---- mutator -------------------------------------------------------------------------------

// The sections of a well-formed entry: [begin, end) of each, in file order.
struct Layout {
  enum { positions, indices, uvs, submeshes, materials, images, count };
  uint64_t begin[count], end[count];
};

bool layout_of(const uint8_t* data, size_t size, Layout& l) {
  if (size < kFixed + 8) return false;
  const uint32_t flags = u32_at(data + 12);
  const uint64_t v = u64_at(data + 32), i = u64_at(data + 40), s = u64_at(data + 48), m = u64_at(data + 56),
                 g = u64_at(data + 64);
  if (v > size || i > size || s > size || m > size || g > size) return false;
  const uint64_t lengths[Layout::count] = {12 * v, 4 * i, (flags & kFlagUvs) ? 8 * v : 0, 12 * s, m, g};
  uint64_t at = kFixed;
  for (int k = 0; k < Layout::count; ++k) l.begin[k] = at, at += lengths[k], l.end[k] = at;
  return at + 8 == size;
}

// One section mutated by libFuzzer, the entry rebuilt around it with its count rewritten.
size_t mutate_section(uint8_t* data, size_t size, size_t max_size, const Layout& l, unsigned seed) {
  const int k = int(seed % Layout::count);
  const uint64_t len = l.end[k] - l.begin[k];
  const size_t others = size - size_t(len);
  if (others >= max_size) return 0;
  const size_t room = max_size - others;
  std::vector<uint8_t> part(room + 1);
  std::memcpy(part.data(), data + l.begin[k], size_t(len));
  size_t n = len;
  if (n == 0) part[0] = uint8_t(seed >> 8), n = 1;  // something for libFuzzer to grow from
  n = LLVMFuzzerMutate(part.data(), n, room);
  // Sizes in whole elements; positions and uvs keep theirs (the vertex count ties them together).
  switch (k) {
    case Layout::positions:
    case Layout::uvs:
      if (n < len) std::memset(part.data() + n, 0, size_t(len - n));
      n = size_t(len);
      break;
    case Layout::indices: n -= n % 12; break;
    case Layout::submeshes: n -= n % 12; break;
    default: break;
  }
  std::vector<uint8_t> out;
  out.reserve(others + n);
  out.insert(out.end(), data, data + l.begin[k]);
  out.insert(out.end(), part.data(), part.data() + n);
  out.insert(out.end(), data + l.end[k], data + size);
  switch (k) {
    case Layout::indices: put_u64(out.data() + 40, n / 4); break;
    case Layout::submeshes: put_u64(out.data() + 48, n / 12); break;
    case Layout::materials: put_u64(out.data() + 56, n); break;
    case Layout::images: put_u64(out.data() + 64, n); break;
    default: break;
  }
  if (out.size() > max_size) return 0;
  std::memcpy(data, out.data(), out.size());
  return out.size();
}

// ---- checks on an accepted entry -------------------------------------------------------------

void check_accepted(const lod::MeshData& m, const lod::HlodSurfaces& s, uint64_t input, const uint8_t* data,
                    uint64_t hash) {
  const size_t v = m.vertex_count();
  if (m.source != "fuzz-source") fail("source name not kept");
  if (m.positions.size() % 3 != 0 || m.indices.size() % 3 != 0) fail("partial vertex or triangle");
  if (input != u64_at(data + 24)) fail("input triangle count not the stored one");
  for (uint32_t i : m.indices)
    if (i >= v) fail("accepted index " + std::to_string(i) + " of " + std::to_string(v) + " vertices");
  for (float x : m.positions)
    if (!std::isfinite(x)) fail("accepted a non-finite position");
  if (!m.uvs.empty() && m.uvs.size() != 2 * v) fail("uvs for some vertices only");
  for (float x : m.uvs)
    if (!std::isfinite(x)) fail("accepted a non-finite uv");
  uint64_t covered = 0;
  for (const lod::Submesh& r : m.submeshes) {
    if (r.first_triangle < covered || uint64_t(r.first_triangle) + r.triangle_count > m.triangle_count())
      fail("accepted a submesh out of order or past the triangles");
    if (r.material < -1 || (r.material >= 0 && size_t(r.material) >= s.materials.size()))
      fail("accepted a submesh naming material " + std::to_string(r.material) + " of " +
           std::to_string(s.materials.size()));
    covered = uint64_t(r.first_triangle) + r.triangle_count;
  }
  for (const lod::ChainMaterial& mat : s.materials)
    for (const std::string* uri : lod::texture_slots(mat)) {
      uint32_t k = 0;
      if (lod::is_embedded_image_uri(*uri, &k) && k >= s.images.size())
        fail("accepted " + *uri + " with " + std::to_string(s.images.size()) + " images");
    }
  for (const lod::EmbeddedImage& img : s.images)
    if (img.type == lod::ImageType::unknown || lod::image_type_of(img.bytes) != img.type)
      fail("accepted an image that is not the type it says");
  // The writer stores what the reader gave, and reading it again gives the same.
  if (lod::Status st = lod::store_hlod_mesh(g_redir, hash, m, input, s); !st) fail("store again: " + st.message);
  lod::MeshData again;
  lod::HlodSurfaces surfaces;
  uint64_t input_again = 0;
  std::string why;
  if (lod::load_hlod_mesh(g_redir, hash, "fuzz-source", again, input_again, &why, &surfaces) != lod::CacheLookup::found)
    fail("an accepted entry stored again is refused: " + why);
  const auto bits_equal = [](const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), 4 * a.size()) == 0);
  };  // bit for bit (a NaN cannot be there: both were checked finite)
  const auto differs = [](const char* what) { fail(std::string("an accepted entry stored again reads back other ") + what); };
  if (!bits_equal(again.positions, m.positions) || again.indices != m.indices) differs("positions or indices");
  if (!bits_equal(again.uvs, m.uvs)) differs("uvs");
  if (input_again != input) differs("input triangles");
  if (again.submeshes.size() != m.submeshes.size()) differs("submesh count");
  for (size_t i = 0; i < m.submeshes.size(); ++i)
    if (again.submeshes[i].first_triangle != m.submeshes[i].first_triangle ||
        again.submeshes[i].triangle_count != m.submeshes[i].triangle_count ||
        again.submeshes[i].material != m.submeshes[i].material)
      differs("submeshes");
  if (surfaces.materials.size() != s.materials.size()) differs("material count");
  if (surfaces.texture_base != s.texture_base) differs("texture base");
  for (size_t i = 0; i < s.materials.size(); ++i) {
    const auto a = lod::texture_slots(s.materials[i]);
    const auto b = lod::texture_slots(std::as_const(surfaces.materials[i]));
    if (s.materials[i].name != surfaces.materials[i].name || s.materials[i].alpha_mode != surfaces.materials[i].alpha_mode)
      differs("material names or alpha modes");
    for (size_t t = 0; t < lod::kTextureSlots; ++t)
      if (*a[t] != *b[t]) differs("texture URIs");
  }
  if (surfaces.images.size() != s.images.size()) differs("image count");
  for (size_t i = 0; i < s.images.size(); ++i)
    if (s.images[i].type != surfaces.images[i].type || s.images[i].bytes != surfaces.images[i].bytes) differs("images");
}

// view_hlod_mesh over the same bytes (aligned, as a node's shared memory is) against load_hlod_mesh.
void agrees_in_place(const uint8_t* data, size_t size, uint64_t hash, bool accepted, const lod::MeshData& loaded) {
  std::vector<uint64_t> words((size + 7) / 8);
  if (size) std::memcpy(words.data(), data, size);
  const std::span<const uint8_t> bytes(reinterpret_cast<const uint8_t*>(words.data()), size);
  lod::HlodMeshInPlace in;
  const lod::Status checked = lod::view_hlod_mesh(bytes, hash, "fuzz-source", true, in);
  if (bool(checked) != accepted)
    fail(std::string("view_hlod_mesh ") + (accepted ? "refused an entry load_hlod_mesh accepts: " + checked.message
                                                     : "accepted an entry load_hlod_mesh refuses"));
  if (!accepted) {
    if (checked.message.rfind("fuzz-source: the cleaned mesh ", 0) != 0) fail("in-place refusal does not say why: " + checked.message);
    return;
  }
  const auto same = [](std::span<const float> a, const std::vector<float>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), 4 * a.size()) == 0);
  };
  for (bool check : {true, false}) {
    lod::HlodMeshInPlace v;
    if (lod::Status st = lod::view_hlod_mesh(bytes, hash, "fuzz-source", check, v); !st) fail("in place: " + st.message);
    if (!same(v.mesh.positions, loaded.positions) || !same(v.mesh.uvs, loaded.uvs) || !same(v.mesh.uvs1, loaded.uvs1) ||
        !same(v.mesh.colors, loaded.colors) ||
        !std::equal(v.mesh.indices.begin(), v.mesh.indices.end(), loaded.indices.begin(), loaded.indices.end()) ||
        v.mesh.submeshes.size() != loaded.submeshes.size() || v.mesh.source != loaded.source)
      fail("the in-place view differs from the loaded mesh");
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* seeds = std::getenv("LOD_FUZZ_WRITE_SEEDS")) {
    write_seeds(seeds);
    std::exit(0);
  }
  std::error_code ec;
  const char* shm = "/dev/shm";
  std::filesystem::path base = std::filesystem::is_directory(shm, ec) ? shm : std::filesystem::temp_directory_path();
  std::string pattern = (base / "lod-hmesh-fuzz-XXXXXX").string();
  if (!::mkdtemp(pattern.data())) fail("cannot make a temporary folder under " + base.string());
  g_dir = std::filesystem::path(pattern) / "in";
  g_redir = std::filesystem::path(pattern) / "again";
  std::filesystem::create_directories(g_dir);
  std::filesystem::create_directories(g_redir);
  std::atexit([] {
    std::error_code e;
    std::filesystem::remove_all(g_dir.parent_path(), e);
  });
  return 0;
}

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t max_size, unsigned int seed) {
  Layout l;
  size_t n = 0;
  if (seed % 4 != 0 && layout_of(data, size, l)) n = mutate_section(data, size, max_size, l, seed / 4);
  if (n == 0) n = LLVMFuzzerMutate(data, size, max_size);
  fix_checksum(data, n);
  return n;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const uint64_t hash = size >= 24 ? u64_at(data + 16) : 0;  // the entry's own: the reader checks it
  const std::filesystem::path path = lod::hlod_mesh_entry_path(g_dir, hash);
  {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd < 0) fail("cannot write " + path.string());
    for (size_t done = 0; done < size;) {
      const ssize_t w = ::write(fd, data + done, size - done);
      if (w <= 0) fail("cannot write " + path.string());
      done += size_t(w);
    }
    ::close(fd);
  }
  lod::MeshData mesh;
  mesh.source = "untouched";
  lod::HlodSurfaces surfaces;
  surfaces.texture_base = "untouched";
  uint64_t input = 12345;
  std::string why;
  const lod::CacheLookup got = lod::load_hlod_mesh(g_dir, hash, "fuzz-source", mesh, input, &why, &surfaces);
  std::filesystem::remove(path);
  if (got != lod::CacheLookup::missing) agrees_in_place(data, size, hash, got == lod::CacheLookup::found, mesh);
  if (got == lod::CacheLookup::missing) fail("an entry that was there is missing");
  if (got == lod::CacheLookup::refused) {
    if (why.rfind(path.string() + ": ", 0) != 0 || why.size() <= path.string().size() + 2)
      fail("refusal does not name the entry and say why: " + why);
    if (mesh.source != "untouched" || !mesh.positions.empty() || surfaces.texture_base != "untouched" ||
        !surfaces.materials.empty() || !surfaces.images.empty() || input != 12345)
      fail("a refused entry changed the outputs: " + why);
    return 0;
  }
  check_accepted(mesh, surfaces, input, data, hash);
  return 0;
}
