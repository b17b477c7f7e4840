#include <gtest/gtest.h>
#include <sys/stat.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <thread>

#include "runtime/lod_asset.h"
#include "test_support.h"
#include "unit/runtime/runtime_fixtures.h"
#include "unit/runtime/truncation_checks.h"

namespace lod {
namespace {

LodChain sample_chain() {
  LodChain c = test::fan_chain("bunny", {9, 4, 2});
  c.normals[1] = -0.0f;  // bit-exact means the sign of zero survives too
  c.positions[4] = 1e-40f;  // a denormal
  return c;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void expect_same_chain(const LodChain& a, const LodChain& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.source_hash, b.source_hash);
  ASSERT_EQ(a.levels.size(), b.levels.size());
  for (size_t k = 0; k < a.levels.size(); ++k) EXPECT_EQ(std::memcmp(&a.levels[k], &b.levels[k], sizeof(LodLevel)), 0);
  EXPECT_TRUE(same_bits(a.positions, b.positions));
  EXPECT_TRUE(same_bits(a.normals, b.normals));
  EXPECT_EQ(a.indices, b.indices);
}

// What `decode` must leave alone when it refuses.
LodChain sentinel() {
  LodChain s;
  s.name = "untouched";
  return s;
}

TEST(LodAsset, RoundTripIsBitExact) {
  const LodChain c = sample_chain();
  const std::vector<uint8_t> bytes = encode_lod_asset(c);
  EXPECT_EQ(bytes.size() % 8, 0u);
  LodChain back;
  const Status st = decode_lod_asset(bytes, "bunny.lod", back);
  ASSERT_TRUE(st) << st.message;
  expect_same_chain(c, back);
  EXPECT_EQ(encode_lod_asset(back), bytes);
}

TEST(LodAsset, RoundTripsChainWithoutNormalsOrName) {
  LodChain c = test::fan_chain("", {1});
  c.normals.clear();
  LodChain back;
  ASSERT_TRUE(decode_lod_asset(encode_lod_asset(c), "x.lod", back));
  expect_same_chain(c, back);
}

TEST(LodAsset, WritesThroughTemporaryFileAndReadsBack) {
  const auto dir = test::temp_dir("asset");
  const auto path = dir / "bunny.lod";
  const LodChain c = sample_chain();
  ASSERT_TRUE(write_lod_asset(path, c));
  size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1u) << "no temporary file is left behind";
  LodChain back;
  const Status st = read_lod_asset(path, back);
  ASSERT_TRUE(st) << st.message;
  expect_same_chain(c, back);
  ASSERT_TRUE(write_lod_asset(path, test::fan_chain("other", {2})));  // replaces
  ASSERT_TRUE(read_lod_asset(path, back));
  EXPECT_EQ(back.name, "other");
}

// Two runs sharing a cache folder may write the same asset at the same moment: both must
// succeed and leave one whole asset (ctest -j2 once failed on exactly this).
TEST(LodAsset, ConcurrentWritersOfOneAssetAllSucceed) {
  const auto dir = test::temp_dir("asset-race");
  const auto path = dir / "same.lod";
  const LodChain a = sample_chain(), b = test::fan_chain("other", {2});
  std::atomic<int> failures{0};
  auto writer = [&](const LodChain& c) {
    for (int i = 0; i < 400; ++i)
      if (!write_lod_asset(path, c)) ++failures;
  };
  std::thread t1(writer, std::cref(a)), t2(writer, std::cref(b));
  t1.join();
  t2.join();
  EXPECT_EQ(failures.load(), 0);
  LodChain back;
  const Status st = read_lod_asset(path, back);
  ASSERT_TRUE(st) << st.message;
  EXPECT_TRUE(back.name == a.name || back.name == b.name);
  size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1u) << "no temporary file is left behind";
}

// Decodes `bytes` as bunny.lod into a sentinel chain, which a refusal must leave untouched.
Status decode_untouched(std::span<const uint8_t> bytes) {
  LodChain out = sentinel();
  const Status st = decode_lod_asset(bytes, "bunny.lod", out);
  if (!st) {
    EXPECT_EQ(out.name, "untouched");
  }
  return st;
}

TEST(LodAsset, RefusesTruncationAtEveryOffset) {
  test::expect_every_truncation_refused(encode_lod_asset(sample_chain()), "bunny.lod", decode_untouched);
}

TEST(LodAsset, RefusesEverySingleFlippedByte) {
  const std::vector<uint8_t> bytes = encode_lod_asset(sample_chain());
  for (size_t at = 0; at < bytes.size(); ++at) {
    for (uint8_t mask : {0x01, 0x80, 0xff}) {
      std::vector<uint8_t> bad = bytes;
      bad[at] ^= mask;
      LodChain out = sentinel();
      ASSERT_FALSE(decode_lod_asset(bad, "bunny.lod", out)) << "byte " << at << " ^ " << int(mask);
      EXPECT_EQ(out.name, "untouched");
    }
  }
}

TEST(LodAsset, RefusesWrongVersionSayingWhichVersions) {
  std::vector<uint8_t> bytes = encode_lod_asset(sample_chain());
  bytes[8] = 2;
  LodChain out;
  const Status st = decode_lod_asset(bytes, "old.lod", out);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("old.lod"), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("version 2"), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("version 1"), std::string::npos) << st.message;
}

TEST(LodAsset, RefusesWrongMagicSayingSo) {
  std::vector<uint8_t> bytes = encode_lod_asset(sample_chain());
  bytes[6] = '\r';  // as a text-mode transfer would
  LodChain out;
  const Status st = decode_lod_asset(bytes, "model.ply", out);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("magic"), std::string::npos) << st.message;
  const std::vector<uint8_t> text(64, 'a');
  EXPECT_FALSE(decode_lod_asset(text, "t.txt", out));
}

TEST(LodAsset, RefusesInvalidChainWithCorrectChecksumNamingTheElement) {
  LodChain c = test::fan_chain("bunny", {6, 3});
  c.indices[c.levels[1].first_index + 4] = 9;
  LodChain out = sentinel();
  const Status st = decode_lod_asset(encode_lod_asset(c), "bunny.lod", out);
  ASSERT_FALSE(st);
  EXPECT_EQ(st.message, "bunny.lod: INDX section: level 1 index 4 references vertex 9 of 5");
  EXPECT_EQ(out.name, "untouched");
}

TEST(LodAsset, ReadingMissingOrEmptyFileNamesIt) {
  const auto dir = test::temp_dir("asset-missing");
  LodChain out;
  Status st = read_lod_asset(dir / "nope.lod", out);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("nope.lod"), std::string::npos) << st.message;
  test::write_bytes(dir / "empty.lod", {});
  st = read_lod_asset(dir / "empty.lod", out);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("empty.lod"), std::string::npos) << st.message;
}

// A directory used to abort with bad_alloc and a FIFO to hang the reader: both are refused
// at once, saying what they are.
TEST(LodAsset, ReadsRegularFilesOnly) {
  const auto dir = test::temp_dir("asset-kinds");
  std::filesystem::create_directories(dir / "folder.lod");
  LodChain out = sentinel();
  Status st = read_lod_asset(dir / "folder.lod", out);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("folder.lod: is a directory"), std::string::npos) << st.message;
  ASSERT_EQ(::mkfifo((dir / "pipe.lod").c_str(), 0600), 0);
  st = read_lod_asset(dir / "pipe.lod", out);  // no writer: opening it blocking would hang
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("pipe.lod: is a FIFO"), std::string::npos) << st.message;
  EXPECT_EQ(out.name, "untouched");
}

TEST(HashBytes, IsDeterministicAndSeeded) {
  std::vector<uint8_t> data(1000);
  for (size_t i = 0; i < data.size(); ++i) data[i] = static_cast<uint8_t>(i * 37 + 11);
  EXPECT_EQ(hash_bytes(data.data(), data.size()), hash_bytes(data.data(), data.size()));
  EXPECT_NE(hash_bytes(data.data(), data.size(), 1), hash_bytes(data.data(), data.size(), 2));
  EXPECT_EQ(hash_bytes(nullptr, 0), hash_bytes(data.data(), 0));
  const uint8_t a[2] = {'a', 0};
  EXPECT_NE(hash_bytes(a, 1), hash_bytes(a, 2));  // trailing zero bytes count
}

TEST(HashBytes, ChangesWithEverySingleByteOfAnyLength) {
  for (size_t n : {1u, 7u, 8u, 9u, 31u, 32u, 33u, 70u}) {
    std::vector<uint8_t> data(n, 0x5a);
    const uint64_t h = hash_bytes(data.data(), n);
    for (size_t at = 0; at < n; ++at) {
      data[at] ^= 0x10;
      EXPECT_NE(hash_bytes(data.data(), n), h) << n << " " << at;
      data[at] ^= 0x10;
    }
  }
}

TEST(HashBytes, SwappedWordsDoNotCollide) {
  uint64_t w[4] = {1, 2, 3, 4}, s[4] = {2, 1, 3, 4}, t[4] = {1, 2, 4, 3};
  EXPECT_NE(hash_bytes(w, 32), hash_bytes(s, 32));
  EXPECT_NE(hash_bytes(w, 32), hash_bytes(t, 32));
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

LodChain chain_with_targets() {
  LodChain c = sample_chain();
  for (size_t k = 0; k + 1 < c.levels.size(); ++k)
    for (uint32_t v = 0; v < c.levels[k].vertex_count; ++v)
      c.morph_targets.push_back((v * 7) % c.levels[k + 1].vertex_count);
  return c;
}

TEST(LodAsset, RoundTripsMorphTargetsInTheirOwnSection) {
  const LodChain c = chain_with_targets();
  const std::vector<uint8_t> bytes = encode_lod_asset(c);
  EXPECT_GT(bytes.size(), encode_lod_asset(sample_chain()).size());
  LodChain back;
  const Status st = decode_lod_asset(bytes, "bunny.lod", back);
  ASSERT_TRUE(st) << st.message;
  expect_same_chain(c, back);
  EXPECT_EQ(back.morph_targets, c.morph_targets);
  EXPECT_EQ(encode_lod_asset(back), bytes);
  // Without them, the section is absent and the chain reads back with none.
  ASSERT_TRUE(decode_lod_asset(encode_lod_asset(sample_chain()), "bunny.lod", back));
  EXPECT_TRUE(back.morph_targets.empty());
}

TEST(LodAsset, RefusesTruncatedOrFlippedMorphTargets) {
  const std::vector<uint8_t> bytes = encode_lod_asset(chain_with_targets());
  test::expect_every_truncation_refused(bytes, "bunny.lod", decode_untouched);
  for (size_t at = 0; at < bytes.size(); ++at) {
    std::vector<uint8_t> bad = bytes;
    bad[at] ^= 0x10;
    LodChain out = sentinel();
    ASSERT_FALSE(decode_lod_asset(bad, "bunny.lod", out)) << "byte " << at;
    EXPECT_EQ(out.name, "untouched");
  }
}

// Assets baked before morph targets carry no MRPH section: they still load, and their level
// changes cannot blend (the bake cache key changed with them, so `lod run` re-bakes anyway).
TEST(LodAsset, AssetWithoutMorphTargetsLoadsAndCannotBlend) {
  LodChain back;
  ASSERT_TRUE(decode_lod_asset(encode_lod_asset(sample_chain()), "old.lod", back));
  EXPECT_FALSE(can_morph_levels(back));
  ASSERT_TRUE(decode_lod_asset(encode_lod_asset(chain_with_targets()), "new.lod", back));
  EXPECT_TRUE(can_morph_levels(back));
}

TEST(LodAsset, RefusesMorphTargetOutOfRangeNamingLevelAndVertex) {
  LodChain c = chain_with_targets();
  c.morph_targets[c.levels[1].first_vertex + 3] = 40;  // level 2 has 4 vertices
  LodChain out = sentinel();
  const Status st = decode_lod_asset(encode_lod_asset(c), "bunny.lod", out);
  ASSERT_FALSE(st);
  EXPECT_EQ(st.message, "bunny.lod: MRPH section: level 1 vertex 3 morphs into vertex 40 of level 2's 4");
  EXPECT_EQ(out.name, "untouched");
}


// Checksum-valid hostile assets (encode checks nothing): each bad field is refused with a
// message naming its section and the element.
TEST(LodAsset, HostileFieldsAreRefusedNamingTheSection) {
  struct Case {
    const char* expect;
    std::function<void(LodChain&)> edit;
  };
  const Case cases[] = {
      {"POSN section: vertex 2 has a non-finite position", [](LodChain& c) { c.positions[7] = std::nanf(""); }},
      {"POSN section: vertex 1 has a huge (beyond 1e18) position", [](LodChain& c) { c.positions[3] = 1e30f; }},
      {"NRML section: vertex 0 has a non-finite normal", [](LodChain& c) { c.normals[0] = INFINITY; }},
      {"INDX section: level 0 index 2 references vertex", [](LodChain& c) { c.indices[2] = 1000; }},
      {"LEVL section: level 1 says l = 9", [](LodChain& c) { c.levels[1].level = 9; }},
      {"LEVL section: level 2 has an invalid bounding sphere", [](LodChain& c) { c.levels[2].bounds.radius = 3e38f; }},
      {"LEVL section: level 1 indices", [](LodChain& c) { c.levels[1].first_index = 1u << 30; }},
      {"LEVL section: level 0 has an invalid error", [](LodChain& c) { c.levels[0].error = -1; }},
      {"MRPH section: level 0 vertex 1 morphs into vertex", [](LodChain& c) { c.morph_targets[1] = 77; }},
  };
  for (const Case& k : cases) {
    LodChain c = chain_with_targets();
    k.edit(c);
    LodChain out = sentinel();
    const Status st = decode_lod_asset(encode_lod_asset(c), "bunny.lod", out);
    ASSERT_FALSE(st) << k.expect;
    EXPECT_EQ(st.message.rfind(std::string("bunny.lod: ") + k.expect, 0), 0u) << st.message;
    EXPECT_EQ(out.name, "untouched");
  }
  // META's counts against the other sections' sizes (bytes edited, checksum fixed).
  std::vector<uint8_t> bytes = encode_lod_asset(chain_with_targets());
  uint64_t meta = 0;
  std::memcpy(&meta, bytes.data() + 16 + 8, 8);
  const uint64_t vertices = 1ull << 40;
  std::memcpy(bytes.data() + meta + 16, &vertices, 8);
  const uint64_t h = hash_bytes(bytes.data(), bytes.size() - 8);
  std::memcpy(bytes.data() + bytes.size() - 8, &h, 8);
  LodChain out = sentinel();
  const Status st = decode_lod_asset(bytes, "bunny.lod", out);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("POSN section is"), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("META says 1099511627776"), std::string::npos) << st.message;
}

// ---- MATL: materials and per-level runs -------------------------------------------------------

LodChain chain_with_materials() {
  LodChain c = test::fan_chain("bunny", {9, 4, 2});
  c.texture_base = "/data/models";
  ChainMaterial a, b;
  a.name = "bark";
  a.base_color_texture = "tex/bark%20d.png";
  a.alpha_mode = AlphaMode::mask;
  a.alpha_cutoff = 0.3f;
  a.metallic_roughness_texture = "tex/mr.png";
  a.normal_texture = "tex/n.png";
  a.occlusion_texture = "tex/ao.png";
  a.emissive_texture = "e.jpg";
  a.normal_scale = 0.75f;
  a.occlusion_strength = 0.5f;
  a.emissive[0] = 0.25f, a.emissive[2] = 1;
  b.name = "leaf";
  b.double_sided = true;
  b.base_color[1] = 0.5f;
  c.materials = {a, b};
  for (uint32_t k = 0; k < c.levels.size(); ++k) {
    const uint32_t n = c.levels[k].index_count;
    const uint32_t first = n / 3 / 2 * 3;
    if (first > 0) c.submeshes.push_back({k, 0, first, 1});
    c.submeshes.push_back({k, first, n - first, k == 0 ? -1 : 0});
  }
  return c;
}

// Offset of the MATL section in an encoded asset (0 when there is none).
uint64_t matl_offset(const std::vector<uint8_t>& bytes) {
  uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 12, 4);
  for (uint32_t s = 0; s < count; ++s)
    if (std::memcmp(bytes.data() + 16 + 24 * s, "MATL", 4) == 0) {
      uint64_t off = 0;
      std::memcpy(&off, bytes.data() + 16 + 24 * s + 8, 8);
      return off;
    }
  return 0;
}

void reseal(std::vector<uint8_t>& bytes) {
  const uint64_t h = hash_bytes(bytes.data(), bytes.size() - 8);
  std::memcpy(bytes.data() + bytes.size() - 8, &h, 8);
}

TEST(LodAssetMaterials, RoundTripKeepsMaterialsAndRuns) {
  const LodChain c = chain_with_materials();
  std::string why;
  ASSERT_TRUE(validate_chain(c, &why)) << why;
  const std::vector<uint8_t> bytes = encode_lod_asset(c);
  ASSERT_NE(matl_offset(bytes), 0u);
  LodChain back;
  const Status st = decode_lod_asset(bytes, "bunny.lod", back);
  ASSERT_TRUE(st) << st.message;
  expect_same_chain(c, back);
  EXPECT_EQ(back.texture_base, c.texture_base);
  ASSERT_EQ(back.materials.size(), 2u);
  EXPECT_EQ(back.materials[0].base_color_texture, "tex/bark%20d.png");
  EXPECT_EQ(back.materials[0].alpha_mode, AlphaMode::mask);
  EXPECT_EQ(back.materials[0].metallic_roughness_texture, "tex/mr.png");
  EXPECT_EQ(back.materials[0].normal_texture, "tex/n.png");
  EXPECT_EQ(back.materials[0].occlusion_texture, "tex/ao.png");
  EXPECT_EQ(back.materials[0].emissive_texture, "e.jpg");
  EXPECT_EQ(back.materials[0].normal_scale, 0.75f);
  EXPECT_EQ(back.materials[0].occlusion_strength, 0.5f);
  EXPECT_EQ(back.materials[0].emissive[0], 0.25f);
  EXPECT_EQ(back.materials[0].emissive[1], 0.0f);
  EXPECT_EQ(back.materials[0].emissive[2], 1.0f);
  EXPECT_TRUE(back.materials[1].normal_texture.empty());
  EXPECT_EQ(back.materials[1].normal_scale, 1.0f);
  EXPECT_TRUE(back.materials[1].double_sided);
  ASSERT_EQ(back.submeshes.size(), c.submeshes.size());
  EXPECT_EQ(level_submeshes(back, 1).size(), 2u);
  EXPECT_EQ(level_submeshes(back, 1)[0].material, 1);
  EXPECT_EQ(encode_lod_asset(back), bytes);
  EXPECT_EQ(matl_offset(encode_lod_asset(test::fan_chain("plain", {4}))), 0u) << "no MATL without materials";
}

TEST(LodAssetMaterials, HostileSectionsAreRefusedNamingWhatIsWrong) {
  struct Case {
    const char* expect;
    size_t at;  // byte within MATL
    uint32_t value;
  };
  const std::vector<uint8_t> good = encode_lod_asset(chain_with_materials());
  const uint64_t matl = matl_offset(good);
  const size_t submeshes = 16 + 12;  // after the header and the texture base "/data/models"
  const size_t first_material = submeshes + 16 * chain_with_materials().submeshes.size();
  const Case cases[] = {
      {"MATL section: 4294967295 materials", 0, 0xffffffffu},
      {"MATL section: 2 materials and 268435456 submeshes need", 4, 1u << 28},
      {"MATL section: texture base of 4000000000 bytes is too long", 8, 4000000000u},
      {"MATL section: layout 3 is newer than this build reads (2)", 12, 3},
      {"MATL section: submesh 0 (level 0) names material 5 of 2", submeshes + 12, 5},
      {"MATL section: submesh 0 (level 0) starts at index 3", submeshes + 4, 3},
      {"MATL section: level 0's material runs cover 0 of its 27 indices", submeshes, 99},
      {"MATL section: material 0 says its name and URIs take 3050 bytes", first_material, 3000},
      {"MATL section: material 0 has a name or URI of 4000000 bytes, at most 4096", first_material + 4, 4000000},
      {"MATL section: material 0 has a name or URI of 5000 bytes", first_material + 40, 5000},
      {"MATL section: material 0 says its name and URIs take 4045 bytes", first_material + 44, 4000},
      {"MATL section: material 0 has a normal texture scale outside [0, 1e6]", first_material + 56, 0x7fc00000u},
      {"MATL section: material 0 has an occlusion strength outside [0, 1]", first_material + 60, 0x40000000u},
      {"MATL section: material 0 has an emissive factor outside [0, 1]", first_material + 68, 0xbf800000u},
      {"MATL section: 3 materials and 6 submeshes need", 0, 3},
      {"MATL section: material 0 has unknown alpha mode 7", first_material + 36, 7},
      {"MATL section: material 0 has a base colour factor outside [0, 1]", first_material + 8, 0x7fc00000u},
  };
  for (const Case& k : cases) {
    std::vector<uint8_t> bytes = good;
    std::memcpy(bytes.data() + matl + k.at, &k.value, 4);
    reseal(bytes);
    LodChain out = sentinel();
    const Status st = decode_lod_asset(bytes, "bunny.lod", out);
    ASSERT_FALSE(st) << k.expect;
    EXPECT_EQ(st.message.rfind(std::string("bunny.lod: ") + k.expect, 0), 0u) << st.message;
    EXPECT_EQ(out.name, "untouched");
  }
  // A control byte in a name (terminal escapes) is refused too.
  std::vector<uint8_t> bytes = good;
  bytes[matl + first_material + 84] = 0x1b;  // the name, after layout 2's 84-byte record
  reseal(bytes);
  LodChain out;
  const Status st = decode_lod_asset(bytes, "bunny.lod", out);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("material 0 name is too long or has control bytes"), std::string::npos) << st.message;
}

// Every string of the new layout lies inside the section: cutting the section's last string
// short (its length one byte longer than what is left) is refused, for each of the six.
TEST(LodAssetMaterials, EveryStringLengthIsCheckedAgainstTheSection) {
  const LodChain c = chain_with_materials();
  const std::vector<uint8_t> good = encode_lod_asset(c);
  const uint64_t matl = matl_offset(good);
  const size_t first_material = 16 + 12 + 16 * c.submeshes.size();
  const size_t offsets[] = {0, 4, 40, 44, 48, 52};  // name, then the URIs in slot order
  for (size_t k = 0; k < 6; ++k) {
    std::vector<uint8_t> bytes = good;
    uint32_t n = 0;
    std::memcpy(&n, bytes.data() + matl + first_material + offsets[k], 4);
    n += 4096 - 64;  // still under kMaxMaterialString, past the section's end
    std::memcpy(bytes.data() + matl + first_material + offsets[k], &n, 4);
    reseal(bytes);
    LodChain out = sentinel();
    const Status st = decode_lod_asset(bytes, "bunny.lod", out);
    ASSERT_FALSE(st) << k;
    EXPECT_NE(st.message.find("MATL section: material 0 says its name and URIs take"), std::string::npos) << st.message;
    EXPECT_EQ(out.name, "untouched");
  }
}

// A bake format 7 asset (MATL layout 0: base colour texture only), the fuzz seed, still reads:
// its materials get the new fields' defaults. (A cache of them rebakes: the bake format is in
// the cache key.)
TEST(LodAssetMaterials, ReadsTheFormat7LayoutWithDefaultsForTheNewFields) {
  const std::filesystem::path seed = std::filesystem::path(LOD_SOURCE_DIR) / "tests/fuzz/corpus/lod/materials0.lod";
  LodChain out;
  const Status st = read_lod_asset(seed, out);
  ASSERT_TRUE(st) << st.message;
  ASSERT_FALSE(out.materials.empty());
  const std::vector<uint8_t> bytes = test::read_bytes(seed);
  uint32_t layout = 1;
  std::memcpy(&layout, bytes.data() + matl_offset(bytes) + 12, 4);
  EXPECT_EQ(layout, 0u) << "the seed is the old layout";
  for (const ChainMaterial& m : out.materials) {
    EXPECT_TRUE(m.normal_texture.empty());
    EXPECT_TRUE(m.emissive_texture.empty());
    EXPECT_EQ(m.normal_scale, 1.0f);
    EXPECT_EQ(m.occlusion_strength, 1.0f);
    EXPECT_EQ(m.emissive[0], 0.0f);
  }
  // Written again, it is the new layout, and reads back the same.
  const std::vector<uint8_t> again = encode_lod_asset(out);
  std::memcpy(&layout, again.data() + matl_offset(again) + 12, 4);
  EXPECT_EQ(layout, 2u);
  LodChain back;
  ASSERT_TRUE(decode_lod_asset(again, "again.lod", back));
  EXPECT_EQ(encode_lod_asset(back), again);
}

// The layout 1 fuzz seed (materials0.lod with every texture slot filled) reads with them.
TEST(LodAssetMaterials, TheLayout1SeedReadsWithEveryTexture) {
  LodChain out;
  const Status st = read_lod_asset(std::filesystem::path(LOD_SOURCE_DIR) / "tests/fuzz/corpus/lod/materials1.lod", out);
  ASSERT_TRUE(st) << st.message;
  ASSERT_FALSE(out.materials.empty());
  EXPECT_EQ(out.materials[0].normal_texture, "n%20map.png");
  EXPECT_EQ(out.materials[0].emissive_texture, "e.jpg");
  EXPECT_EQ(out.materials[0].normal_scale, 0.5f);
  EXPECT_EQ(out.materials[0].emissive[1], 0.5f);
  for (uint8_t t : out.materials[0].tex_coords) EXPECT_EQ(t, 0) << "layout 1 reads TEXCOORD_0 everywhere";
}

// ---- TEX1, COL0 and MATL layout 2 (bake format 9) ------------------------------------------------

LodChain chain_with_attributes() {
  LodChain c = chain_with_materials();
  const size_t nv = c.positions.size() / 3;
  for (size_t v = 0; v < nv; ++v) {
    const float a = float(v) / float(nv);
    c.uvs1.insert(c.uvs1.end(), {a, 1 - a});
    c.colors.insert(c.colors.end(), {a, 0.5f, 1 - a, 1});
  }
  c.uv1_errors.assign(c.levels.size(), 0.f);
  c.color_errors.assign(c.levels.size(), 0.f);
  for (size_t k = 1; k < c.levels.size(); ++k) c.uv1_errors[k] = 0.01f * float(k), c.color_errors[k] = 0.02f * float(k);
  c.materials[0].tex_coords = {0, 1, 1, 0, 1};
  return c;
}

// Offset and size of section `tag` in an encoded asset (size 0 when there is none).
std::pair<uint64_t, uint64_t> section_of(const std::vector<uint8_t>& bytes, const char* tag) {
  uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 12, 4);
  for (uint32_t s = 0; s < count; ++s)
    if (std::memcmp(bytes.data() + 16 + 24 * s, tag, 4) == 0) {
      uint64_t off = 0, size = 0;
      std::memcpy(&off, bytes.data() + 16 + 24 * s + 8, 8);
      std::memcpy(&size, bytes.data() + 16 + 24 * s + 16, 8);
      return {off, size};
    }
  return {0, 0};
}

TEST(LodAssetAttributes, RoundTripKeepsColoursTexcoord1AndTexCoordsPerSlot) {
  const LodChain c = chain_with_attributes();
  std::string why;
  ASSERT_TRUE(validate_chain(c, &why)) << why;
  const std::vector<uint8_t> bytes = encode_lod_asset(c);
  EXPECT_NE(section_of(bytes, "TEX1").second, 0u);
  EXPECT_NE(section_of(bytes, "COL0").second, 0u);
  LodChain back;
  const Status st = decode_lod_asset(bytes, "bunny.lod", back);
  ASSERT_TRUE(st) << st.message;
  EXPECT_TRUE(same_bits(back.uvs1, c.uvs1));
  EXPECT_TRUE(same_bits(back.colors, c.colors));
  EXPECT_EQ(back.uv1_errors, c.uv1_errors);
  EXPECT_EQ(back.color_errors, c.color_errors);
  EXPECT_EQ(back.materials[0].tex_coords, c.materials[0].tex_coords);
  EXPECT_EQ(encode_lod_asset(back), bytes);
  const std::vector<uint8_t> plain = encode_lod_asset(test::fan_chain("plain", {4}));
  EXPECT_EQ(section_of(plain, "TEX1").second, 0u) << "no TEX1 without a second uv set";
  EXPECT_EQ(section_of(plain, "COL0").second, 0u) << "no COL0 without colours";
}

// Truncated or forged sections are refused naming the section; nothing is half-loaded.
TEST(LodAssetAttributes, RefusesForgedOrTruncatedTex1AndCol0) {
  const std::vector<uint8_t> good = encode_lod_asset(chain_with_attributes());
  struct Case {
    const char* tag;
    uint64_t at;      // byte within the section, or UINT64_MAX to shrink the section's size by 4
    uint32_t value;
    const char* expect;
  };
  const Case cases[] = {
      {"TEX1", 0, 7, "TEX1 section is"},            // level count forged
      {"COL0", 0, 0xffffffffu, "COL0 section is"},  // level count forged
      {"TEX1", UINT64_MAX, 0, "TEX1 section is"},   // a value short
      {"COL0", UINT64_MAX, 0, "COL0 section is"},
      {"COL0", 4 + 4 * 3 + 4 * 5, 0x7fc00000u, "COL0 section: vertex 1 has a huge or non-finite colour"},
      {"TEX1", 4 + 4 * 3 + 8 * 2, 0x7f800000u, "TEX1 section: vertex 2 has a huge or non-finite uv1"},
      {"COL0", 4 + 4, 0xbf800000u, "COL0 section: level 1 has an invalid colour error"},
  };
  for (const Case& k : cases) {
    std::vector<uint8_t> bytes = good;
    const auto [off, size] = section_of(bytes, k.tag);
    ASSERT_NE(size, 0u);
    if (k.at == UINT64_MAX) {
      uint32_t count = 0;
      std::memcpy(&count, bytes.data() + 12, 4);
      for (uint32_t s = 0; s < count; ++s)
        if (std::memcmp(bytes.data() + 16 + 24 * s, k.tag, 4) == 0) {
          const uint64_t shorter = size - 4;
          std::memcpy(bytes.data() + 16 + 24 * s + 16, &shorter, 8);
        }
    } else {
      std::memcpy(bytes.data() + off + k.at, &k.value, 4);
    }
    reseal(bytes);
    LodChain out = sentinel();
    const Status st = decode_lod_asset(bytes, "bunny.lod", out);
    ASSERT_FALSE(st) << k.expect;
    EXPECT_EQ(st.message.rfind(std::string("bunny.lod: ") + k.expect, 0), 0u) << st.message;
    EXPECT_EQ(out.name, "untouched");
  }
  // Cut anywhere in the new sections: refused (truncated, or the checksum).
  const auto [col0, col0_size] = section_of(good, "COL0");
  for (uint64_t cut = section_of(good, "TEX1").first; cut < col0 + col0_size; cut += 13) {
    const std::vector<uint8_t> bytes(good.begin(), good.begin() + std::ptrdiff_t(cut));
    LodChain out = sentinel();
    EXPECT_FALSE(decode_lod_asset(bytes, "bunny.lod", out)) << cut;
    EXPECT_EQ(out.name, "untouched");
  }
}

TEST(LodAssetAttributes, RefusesATexCoordPastTexcoord1AndNonZeroPadding) {
  const LodChain c = chain_with_attributes();
  const std::vector<uint8_t> good = encode_lod_asset(c);
  const uint64_t matl = matl_offset(good);
  const size_t first_material = 16 + 12 + 16 * c.submeshes.size();
  {
    std::vector<uint8_t> bytes = good;
    bytes[matl + first_material + 76 + 2] = 2;  // the normal slot reads TEXCOORD_2
    reseal(bytes);
    LodChain out = sentinel();
    const Status st = decode_lod_asset(bytes, "bunny.lod", out);
    ASSERT_FALSE(st);
    EXPECT_NE(st.message.find("MATL section: material 0 normal texture reads TEXCOORD_2"), std::string::npos) << st.message;
    EXPECT_EQ(out.name, "untouched");
  }
  {
    std::vector<uint8_t> bytes = good;
    bytes[matl + first_material + 82] = 1;
    reseal(bytes);
    LodChain out = sentinel();
    const Status st = decode_lod_asset(bytes, "bunny.lod", out);
    ASSERT_FALSE(st);
    EXPECT_NE(st.message.find("MATL section: material 0 has non-zero padding byte 82"), std::string::npos) << st.message;
  }
}

// The layout 2 fuzz seed (materials1.lod's chain with colours, TEXCOORD_1 and a texture reading
// it) reads with them.
TEST(LodAssetAttributes, TheAttributesSeedReads) {
  LodChain out;
  const Status st = read_lod_asset(std::filesystem::path(LOD_SOURCE_DIR) / "tests/fuzz/corpus/lod/attributes2.lod", out);
  ASSERT_TRUE(st) << st.message;
  EXPECT_FALSE(out.colors.empty());
  EXPECT_FALSE(out.uvs1.empty());
  ASSERT_FALSE(out.materials.empty());
  EXPECT_EQ(out.materials[0].tex_coords[1], 1);
}


// ---- IMGS: images embedded in the source, kept in the asset (bake format 10) ----------------

// Enough of a PNG and a JPEG for the asset: their signatures, then bytes no reader here decodes.
EmbeddedImage fake_image(ImageType type, size_t size) {
  EmbeddedImage img;
  img.type = type;
  img.bytes = type == ImageType::png ? std::vector<uint8_t>{0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a}
                                     : std::vector<uint8_t>{0xff, 0xd8, 0xff, 0xe0};
  for (size_t i = img.bytes.size(); i < size; ++i) img.bytes.push_back(uint8_t(i * 7));
  return img;
}

LodChain chain_with_images() {
  LodChain c = chain_with_materials();
  c.images = {fake_image(ImageType::png, 45), fake_image(ImageType::jpeg, 19)};
  c.materials[0].base_color_texture = embedded_image_uri(1);
  c.materials[0].emissive_texture = embedded_image_uri(0);
  c.materials[1].normal_texture = embedded_image_uri(1);
  return c;
}

// The section table entry of `tag`: its size is patched through it.
size_t table_entry_of(const std::vector<uint8_t>& bytes, const char* tag) {
  uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 12, 4);
  for (uint32_t s = 0; s < count; ++s)
    if (std::memcmp(bytes.data() + 16 + 24 * s, tag, 4) == 0) return 16 + 24 * size_t(s);
  return 0;
}

TEST(LodAssetImages, RoundTripKeepsEveryImageByteForByteAndTheSlotsNamingThem) {
  const LodChain c = chain_with_images();
  std::string why;
  ASSERT_TRUE(validate_chain(c, &why)) << why;
  const std::vector<uint8_t> bytes = encode_lod_asset(c);
  const auto [off, size] = section_of(bytes, "IMGS");
  EXPECT_EQ(size, 16u + 2 * 16 + 45 + 19);
  LodChain back;
  const Status st = decode_lod_asset(bytes, "bunny.lod", back);
  ASSERT_TRUE(st) << st.message;
  ASSERT_EQ(back.images.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(back.images[k].type, c.images[k].type);
    EXPECT_EQ(back.images[k].bytes, c.images[k].bytes);
  }
  EXPECT_EQ(back.materials[0].base_color_texture, "embedded:1");
  EXPECT_EQ(back.materials[1].normal_texture, "embedded:1");
  EXPECT_EQ(encode_lod_asset(back), bytes);
  EXPECT_EQ(section_of(encode_lod_asset(chain_with_materials()), "IMGS").second, 0u) << "no IMGS without images";
}

TEST(LodAssetImages, RefusesForgedCountsLengthsTypesAndSignatures) {
  const std::vector<uint8_t> good = encode_lod_asset(chain_with_images());
  const uint64_t imgs = section_of(good, "IMGS").first;
  struct Case {
    uint64_t at;  // byte within the section
    std::vector<uint8_t> value;
    const char* expect;
  };
  const auto u32 = [](uint32_t v) { return std::vector<uint8_t>{uint8_t(v), uint8_t(v >> 8), uint8_t(v >> 16), uint8_t(v >> 24)}; };
  const auto u64 = [&](uint64_t v) {
    std::vector<uint8_t> b = u32(uint32_t(v)), hi = u32(uint32_t(v >> 32));
    b.insert(b.end(), hi.begin(), hi.end());
    return b;
  };
  const Case cases[] = {
      {0, u32(0xffffffffu), "IMGS section: 4294967295 images, at most 4096"},
      {0, u32(3), "IMGS section: 112 bytes, but 3 images of 64 bytes need 64 + 64"},
      {4, u32(2), "IMGS section: layout 2 is newer than this build reads"},
      {4, u32(0), "IMGS section: layout 0 does not exist"},
      {8, u64(uint64_t(1) << 40), "IMGS section: 1099511627776 image bytes, at most 1073741824"},
      {8, u64(63), "IMGS section: 112 bytes, but 2 images of 63 bytes need 48 + 63"},
      {16, u64(uint64_t(1) << 62), "IMGS section: image 0 is 4611686018427387904 bytes, at most 268435456"},
      {16, u64(44), "IMGS section: images' lengths add up to 63 bytes, the section says 64"},
      {24, {3}, "IMGS section: image 0 has type 3 (1 PNG, 2 JPEG)"},
      {24, {0}, "IMGS section: image 0 has type 0 (1 PNG, 2 JPEG)"},
      {24 + 16 + 5, {1}, "IMGS section: image 1 has non-zero padding byte 13"},
      {24, {2}, "IMGS section: embedded image 0 is not the PNG or JPEG its type says"},
      {48, {0x88}, "IMGS section: embedded image 0 is not the PNG or JPEG its type says"},
  };
  for (const Case& k : cases) {
    std::vector<uint8_t> bytes = good;
    std::memcpy(bytes.data() + imgs + k.at, k.value.data(), k.value.size());
    reseal(bytes);
    LodChain out = sentinel();
    const Status st = decode_lod_asset(bytes, "bunny.lod", out);
    ASSERT_FALSE(st) << k.expect;
    EXPECT_EQ(st.message.rfind(std::string("bunny.lod: ") + k.expect, 0), 0u) << st.message;
    EXPECT_EQ(out.name, "untouched");
  }
}

TEST(LodAssetImages, RefusesASlotNamingAnImageTheAssetLacks) {
  LodChain c = chain_with_images();
  c.materials[1].occlusion_texture = "embedded:2";
  std::string why;
  EXPECT_FALSE(validate_chain(c, &why));
  LodChain out = sentinel();
  const Status st = decode_lod_asset(encode_lod_asset(c), "bunny.lod", out);
  ASSERT_FALSE(st);
  EXPECT_EQ(st.message, "bunny.lod: MATL section: material 1 occlusion texture names embedded image 'embedded:2' of 2");
  c.images.clear();  // no IMGS section at all: every embedded slot is dangling
  EXPECT_FALSE(decode_lod_asset(encode_lod_asset(c), "bunny.lod", out));
  EXPECT_EQ(out.name, "untouched");
}

// Cut anywhere: the file (the checksum or the section table says so), and the section alone
// (its size shortened to every length, the checksum made right again: IMGS's own checks).
TEST(LodAssetImages, RefusesTruncationAtEveryOffsetOfTheFileAndOfTheSection) {
  const std::vector<uint8_t> good = encode_lod_asset(chain_with_images());
  test::expect_every_truncation_refused(good, "bunny.lod", decode_untouched);
  const size_t entry = table_entry_of(good, "IMGS");
  const uint64_t size = section_of(good, "IMGS").second;
  for (uint64_t shorter = 0; shorter < size; ++shorter) {
    std::vector<uint8_t> bytes = good;
    std::memcpy(bytes.data() + entry + 16, &shorter, 8);
    reseal(bytes);
    LodChain out = sentinel();
    const Status st = decode_lod_asset(bytes, "bunny.lod", out);
    ASSERT_FALSE(st) << shorter;
    EXPECT_EQ(st.message.rfind("bunny.lod: IMGS section: ", 0), 0u) << st.message;
    EXPECT_EQ(out.name, "untouched");
  }
}

// The IMGS fuzz seed (attributes2.lod's chain with two embedded images that three slots name)
// reads with them.
TEST(LodAssetImages, TheImagesSeedReads) {
  LodChain out;
  const Status st = read_lod_asset(std::filesystem::path(LOD_SOURCE_DIR) / "tests/fuzz/corpus/lod/images10.lod", out);
  ASSERT_TRUE(st) << st.message;
  ASSERT_EQ(out.images.size(), 2u);
  EXPECT_EQ(out.images[0].type, ImageType::png);
  EXPECT_EQ(out.images[1].type, ImageType::jpeg);
  EXPECT_EQ(out.materials[0].base_color_texture, "embedded:1");
}

TEST(EmbeddedImage, TypesBySignatureAndParsesItsUriForm) {
  EXPECT_EQ(image_type_of(fake_image(ImageType::png, 8).bytes), ImageType::png);
  EXPECT_EQ(image_type_of(fake_image(ImageType::jpeg, 3).bytes), ImageType::jpeg);
  EXPECT_EQ(image_type_of(std::vector<uint8_t>{0x89, 'P', 'N', 'G'}), ImageType::unknown) << "a cut signature";
  EXPECT_EQ(image_type_of(std::vector<uint8_t>{'G', 'I', 'F', '8', '9', 'a', 0, 0}), ImageType::unknown);
  uint32_t k = 0;
  EXPECT_TRUE(is_embedded_image_uri("embedded:17", &k));
  EXPECT_EQ(k, 17u);
  EXPECT_TRUE(is_embedded_image_uri("embedded:99999", &k));
  EXPECT_EQ(k, UINT32_MAX) << "past kMaxEmbeddedImages";
  EXPECT_TRUE(is_embedded_image_uri("embedded:", &k));
  EXPECT_EQ(k, UINT32_MAX);
  EXPECT_TRUE(is_embedded_image_uri("embedded:1x", &k));
  EXPECT_EQ(k, UINT32_MAX);
  EXPECT_FALSE(is_embedded_image_uri("tex/embedded:1.png"));
  EXPECT_FALSE(is_embedded_image_uri("embedded%3A1"));
  EXPECT_EQ(embedded_image_uri(3), "embedded:3");
}

}  // namespace
}  // namespace lod
