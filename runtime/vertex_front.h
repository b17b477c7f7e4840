// VertexFront: the active front of a VertexTree for one view-dependent object, and its
// per-frame refine/coarsen update.
//
// Hoppe 1997 ("View-dependent refinement of progressive meshes") for the refinement criteria
// (frustum, normal cone, screen-space error) and forced splits; Berkey and Song and
// El-Sana & Varshney 1999 for the dependencies that keep every front a valid mesh (a node
// splits, and a pair merges, only when the neighbours it had at build time are active);
// Luebke's LOD survey for temporal coherence and coherent arrays: active vertices and triangles live
// in dense arrays kept packed by swaps, so a consumer draws triangles [0, tri_count).
//
// Only changed nodes are visited: each active node is filed in calendars of view-motion
// buckets by how much the view may change before its decision could (its slack: eye travel
// for the error and normal-cone tests, plane turning scaled by the node's distance for the
// frustum); a frame visits only the buckets the accumulated motion has passed, plus nodes just
// made by splits and collapses, in node order with their records prefetched. A teleport passes
// every bucket and so re-evaluates the whole front. Only a pair's first child watches whether
// the pair should merge. front_stale_decisions checks that nothing a full re-evaluation would
// change was missed.
//
// Everything is allocated by front_init; front_update allocates nothing and owns no threads.
// Fronts of different objects (or of one tree by different views) are independent, and so are
// the fronts of the regions of one tree (vertex_tree_regions), which may run on different
// threads at once.
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "runtime/vertex_tree.h"
#include "runtime/view.h"

namespace lod {

// The camera as seen from the object (object space: transform undone, distances in object units).
struct FrontView {
  float eye[3] = {0, 0, 0};
  float planes[6][4] = {};  // normalized, inside when dot(n, p) + w >= 0
  float focal_pixels = 1;   // pixels per unit of size at distance 1 (scale free)
};

// `view` seen from an object placed as ObjectSet does: world = R_y(yaw) * (scale * p) + position.
FrontView front_view_of(const View& view, const float position[3], float scale, float yaw);
// The same for a full rotation: world = R(q) * (scale * p) + position, q = x y z w (normalised here).
FrontView front_view_of(const View& view, const float position[3], float scale, const float rotation[4]);

enum class FrontEventKind : uint8_t { split, collapse, collapse_begin, collapse_cancel };

struct FrontEvent {
  uint32_t node;  // the parent: split into / collapsed from its two children
  FrontEventKind kind;
};

struct FrontParams {
  double time = 0;                // seconds, increasing; used by deferred collapses
  float collapse_delay = 0;       // > 0: collapses wait this long (children morph onto the parent)
  uint32_t max_triangles = 0;     // hard cap on active triangles; 0 = none
  uint32_t target_triangles = 0;  // feedback: the pixel threshold moves to meet this; 0 = fixed
  float min_threshold = 0.05f;    // pixels
  float max_threshold = 1.0e5f;
  uint32_t max_operations = 0;  // splits + collapses per frame; 0 = unlimited
  // Hysteresis: a node splits when its projected error exceeds the threshold, but its children
  // merge back only when it falls below threshold / hysteresis, so decisions do not flicker
  // and a moving camera re-judges far fewer nodes. 1 = none.
  float hysteresis = 1.5f;
};

struct FrontStats {
  uint32_t splits = 0;
  uint32_t collapses = 0;
  uint32_t visited = 0;  // nodes evaluated this frame
  uint32_t blocked = 0;  // splits refused by max_triangles or max_operations
  uint32_t active_tris = 0;
  uint32_t active_vertices = 0;
  float threshold = 0;     // pixel threshold used this frame
  bool full_pass = false;  // every active node was evaluated (teleport / first frame)
};

struct VertexFront {
  static constexpr uint8_t kBelow = 0, kActive = 1, kSplit = 2;

  // Per-node arrays a frame reads at random live on huge pages (fewer TLB misses).
  template <class T>
  using NodeArray = std::vector<T, HugePageAllocator<T>>;

  NodeArray<uint8_t> state;           // per node
  // Per node: how many of its children are active (kKidsMask bits), and kFirstChild when it is
  // its parent's first child, the one that judges whether the parent should merge.
  static constexpr uint8_t kKidsMask = 3, kFirstChild = 0x80;
  NodeArray<uint8_t> kids;
  std::vector<uint32_t> active;       // active node ids, [0, active_count)
  NodeArray<uint32_t> active_pos;     // per node: index in `active`
  std::vector<uint32_t> tri_indices;  // 3 node ids per active triangle, [0, 3 * tri_count)
  std::vector<uint32_t> tri_face;     // face id per triangle slot
  std::vector<uint32_t> face_slot;    // per face: triangle slot or kNoNode
  uint32_t active_count = 0;
  uint32_t tri_count = 0;
  float threshold = 1;  // pixel threshold (tau), moved by feedback
  // The region of the tree this front covers (vertex_tree_regions), or kSharedRegion for all of
  // it. A region's front indexes its per-node and per-face arrays by the numbering's local ids
  // (at, at_face), so they hold its own region only; a whole-tree front by node and face ids.
  uint8_t region = kSharedRegion;
  std::shared_ptr<const RegionNumbering> numbering;  // null for the whole tree
  const uint32_t* node_local = nullptr;               // numbering->local.data(), or null
  const uint32_t* face_local = nullptr;
  uint32_t local_leaves = 0;  // local ids below it are leaves
  uint32_t at(uint32_t node) const { return node_local ? node_local[node] : node; }
  uint32_t at_face(uint32_t face) const { return face_local ? face_local[face] : face; }
  uint32_t inner_at(uint32_t node) const { return at(node) - local_leaves; }  // interior nodes only
  // In this front's region, or a fixed leaf (in every region).
  bool covers(uint32_t node) const {
    return !numbering || numbering->region[node] == region || numbering->region[node] == kSharedRegion;
  }
  bool covers_face(const VertexTree& tree, uint32_t face) const {
    return !numbering || face_region(tree, numbering->region, face) == region;
  }

  // Two calendars of view-motion buckets: calendar 0 by eye travel, plane offset and threshold
  // changes (object units); calendar 1 by frustum-plane turning (radians), which moves a plane
  // less near the eye than far away. A node may sit in both, plus a retry-next-frame bucket.
  // Buckets are lists of fixed chunks of (node, stamp) entries from one pool, appended and
  // drained as arrays; unfiling a node only bumps its stamp, so its old entries read as dead
  // (no neighbours to relink), and a bucket is compacted once mostly dead.
  static constexpr uint32_t kChunkEntries = 63;
  struct Chunk {
    uint32_t next, count;
    uint32_t node[kChunkEntries];
    uint32_t stamp[kChunkEntries];
  };
  struct Bucket {
    uint32_t head = kNoNode;  // newest chunk
    uint32_t live = 0, total = 0;
  };
  struct Filing {
    uint32_t stamp = 0;
    uint16_t bucket[2] = {0xffff, 0xffff};  // per calendar; 0xffff = not filed there
  };
  NodeArray<Filing> filing;     // per node
  std::vector<Bucket> buckets;  // per calendar kBuckets + 1; the last of calendar 0: retry
  NodeArray<Chunk> chunks;
  uint32_t free_chunk = kNoNode;
  double motion[2] = {0, 0};          // accumulated bound on view change per calendar
  int64_t cursor[2] = {0, 0};         // first bucket not yet visited
  double bucket_width[2] = {1, 1};
  double pending_motion = 0;  // from last frame's threshold change (calendar 0)
  float center[3] = {0, 0, 0};
  float extent = 0;  // radius of the sphere at `center` holding every node
  bool has_view = false;
  FrontView last_view;

  // Collapses blocked by a finer neighbour wait on it (intrusive lists keyed by the neighbour)
  // and are woken when it becomes active, so they are not polled every frame.
  NodeArray<uint32_t> wait_on, wait_next, wait_prev, wait_head;  // per node
  uint32_t waiting = 0;                                            // nodes on some wait list

  // Deferred collapses (geomorphing): per interior node the time it may collapse.
  std::vector<double> pending_until;  // < 0: not pending
  std::vector<uint32_t> pending, pending_pos;
  uint32_t pending_count = 0;

  // Scratch, sized once.
  std::vector<uint32_t> queue, stack;
  std::vector<FrontEvent> events;
  uint32_t event_count = 0;

  std::span<const uint32_t> triangles() const { return {tri_indices.data(), 3 * size_t(tri_count)}; }
  std::span<const uint32_t> vertices() const { return {active.data(), active_count}; }
  std::span<const FrontEvent> frame_events() const { return {events.data(), event_count}; }
};

// Sizes everything for `tree` and sets the front to the base mesh (the roots).
void front_init(VertexFront& front, const VertexTree& tree, float threshold);

// The same for one region of vertex_tree_regions: the region's roots, every fixed leaf and the
// region's base faces. Fronts of different regions of one tree touch disjoint nodes, faces and
// per-node arrays, so they may be updated on different threads at once, each result the same
// as alone; together their triangles are the whole mesh (fronts_compact_mesh).
void front_init(VertexFront& front, const VertexTree& tree, float threshold, std::span<const uint8_t> regions,
                uint8_t region);
// The same with the regions' numbering built once (number_regions) and shared by their fronts.
void front_init(VertexFront& front, const VertexTree& tree, float threshold,
                std::shared_ptr<const RegionNumbering> numbering, uint8_t region);

// Bytes the front's arrays hold (their capacity; of the calendar's chunk pool, the chunks in
// use so far, as the rest of its reserve is never touched), the shared numbering not included.
size_t front_memory_bytes(const VertexFront& front);

// Threshold feedback (front_update does it when target_triangles > 0): the next pixel threshold
// for `triangles` active against `target` (triangles grow about as 1 / threshold^2), clamped
// to the params' range. Fronts sharing one threshold (regions of one object) use it on their
// summed triangles and then front_set_threshold on each.
float front_next_threshold(float threshold, uint64_t triangles, uint64_t target, const FrontParams& params);
// Moves the threshold, telling the motion calendar how far decisions may have moved.
void front_set_threshold(VertexFront& front, float threshold);

// One frame: visits expired and new nodes, collapses where no refinement is wanted for the
// parent, then splits (forcing missing dependencies first) where a node is in the frustum,
// not back-facing and its projected error exceeds the threshold, within max_triangles and
// max_operations; finally moves the threshold towards target_triangles. The front is a valid
// mesh after every call. Events of this frame are in front.frame_events().
FrontStats front_update(VertexFront& front, const VertexTree& tree, const FrontView& view,
                        const FrontParams& params);

// Splits everything (the input mesh) / collapses everything (the base mesh); no limits.
void front_refine_all(VertexFront& front, const VertexTree& tree);
void front_coarsen_all(VertexFront& front, const VertexTree& tree);

// How much of a triangulation check applies: inputs with orientation flips or edges in three
// faces can only be checked for valid corners; consistently oriented ones also for each
// directed edge being used once; closed ones also for every edge having two faces.
enum class EdgeCheck : uint8_t { corners, oriented, closed };

// Checks the active triangles (of the front's region only: its leaves and faces; a region is
// open along its seam, so `closed` is checked as `oriented` there): corners are active nodes and the active ancestors of each
// face's leaves, no repeated corner, the packed arrays agree with each other; from `oriented`
// on each directed edge used once (consistent orientation, no edge in more than two faces);
// with `closed` every edge in exactly two faces (no cracks, no T-junctions). Allocates (a test and
// `lod run --validate` tool, not a per-frame stage). `message` names the first bad element.
bool check_front(const VertexFront& front, const VertexTree& tree, EdgeCheck edges, std::string* message);

// Checks temporal coherence against a full re-evaluation: counts the decisions of `front` that
// disagree with `view` at the front's threshold (active nodes that want to split; split nodes
// whose children are active, which want to merge and whose dependencies are active). Nodes
// left for a retry next frame (a limit, a split made late in the frame) and deferred merges are
// not counted. A test and `--validate` tool; `message` names the first.
uint32_t front_stale_decisions(const VertexFront& front, const VertexTree& tree, const FrontView& view,
                               const FrontParams& params, std::string* message);

// The front as a compact mesh for a consumer: positions of the active vertices in active-list
// order (taken from `shown`, xyz per node id, e.g. geomorphed positions; the tree's own
// positions when `shown` is empty) and triangles [0, tri_count) indexing them. `positions`
// holds at least 3 * active_count floats, `indices` 3 * tri_count. Returns tri_count.
uint32_t front_compact_mesh(std::span<float> positions, std::span<uint32_t> indices, const VertexFront& front,
                            const VertexTree& tree, std::span<const float> shown);

// The fronts of all regions of one tree as one compact mesh: vertices of fronts[0] in its
// active order, then each other front's active nodes outside kSharedRegion (fixed leaves are
// active in every region and written once), so seams share vertices. `node_index` is scratch
// of node_count entries. Writes *vertex_count and returns the triangle count; positions and
// indices need room for the summed active vertices and triangles.
uint32_t fronts_compact_mesh(std::span<float> positions, std::span<uint32_t> indices, std::span<uint32_t> node_index,
                             std::span<const VertexFront* const> fronts, const VertexTree& tree,
                             std::span<const float> shown, uint32_t* vertex_count);

// Texture coordinates of the same compact meshes, in the same vertex order: uv per active vertex
// from `shown_uvs` (uv per node id, e.g. geomorphed; the tree's own uvs when empty). The tree
// must have uvs; `uvs` holds 2 floats per written vertex. Return the vertices written.
uint32_t front_compact_uvs(std::span<float> uvs, const VertexFront& front, const VertexTree& tree,
                           std::span<const float> shown_uvs);
uint32_t fronts_compact_uvs(std::span<float> uvs, std::span<const VertexFront* const> fronts, const VertexTree& tree,
                            std::span<const float> shown_uvs);
// The same for any per-node column of `width` floats (VertexTree::uvs1, colors, normals):
// `per_node` holds width floats per node id, `out` width per written vertex. Return the
// vertices written.
uint32_t front_compact_column(std::span<float> out, size_t width, const VertexFront& front,
                              std::span<const float> per_node);
uint32_t fronts_compact_column(std::span<float> out, size_t width, std::span<const VertexFront* const> fronts,
                               std::span<const float> per_node);
// The node id of every vertex fronts_compact_mesh writes, in its order (`nodes` holds the summed
// active vertices less the repeated fixed ones). Returns the count written.
uint32_t fronts_compact_nodes(std::span<uint32_t> nodes, std::span<const VertexFront* const> fronts);

// Checks a plain indexed triangle list: indices < vertex_count, no repeated corner; from
// `oriented` on each directed edge at most once; with `closed` every edge also used the other
// way round.
// Allocates. `message` names the first bad triangle or edge.
bool check_triangles(std::span<const uint32_t> indices, uint32_t vertex_count, EdgeCheck edges,
                     std::string* message);

// True when every directed edge of the list has its reverse (a closed, oriented surface).
bool triangles_closed(std::span<const uint32_t> indices);

// The strongest check a full-detail mesh passes itself (what its fronts are held to).
EdgeCheck edge_check_of(std::span<const uint32_t> indices);

}  // namespace lod
