/* lodkit's C API (C99), for engines in other languages (C# P/Invoke, Python ctypes, Rust).
 *
 * Object calls and lod_commit may come from any thread (the library serialises them); frames
 * may be acquired from any thread by any number of consumers. Nothing here aborts the host:
 * a bad path, a stale handle or a bad view gives a nonzero return (or 0 / NULL) and, where
 * there is an error buffer, a message naming the file or value. */
#ifndef LODKIT_LODKIT_H
#define LODKIT_LODKIT_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lod_service lod_service;
typedef struct lod_frame lod_frame;
typedef uint64_t lod_object; /* 0 is never a valid handle */
typedef uint32_t lod_model;

typedef struct lod_transform {
  float position[3];
  float rotation[4]; /* x y z w */
  float scale;
} lod_transform;

/* The ranges the setters accept, both ends included unless stated. A value outside (NaN and
 * infinities included) is refused: nonzero return, lod_last_error() naming the value, the
 * setting unchanged. */
#define LOD_MIN_BUDGET 1u                 /* lod_set_budget: >= 1 */
#define LOD_MAX_PIXEL_ERROR 10000.0f      /* lod_set_pixel_error: (0, 10000] pixels, 0 excluded */
#define LOD_MAX_HYSTERESIS 10.0f          /* lod_set_hysteresis: [0, 10] */
#define LOD_MAX_BLEND_SECONDS 60.0f       /* lod_set_blend_seconds: [0, 60] seconds */
#define LOD_MIN_FOV_Y_DEG 0.001f          /* lod_view.fov_y_deg: [0.001, 179] degrees */
#define LOD_MAX_FOV_Y_DEG 179.0f

/* A view is refused unless eye, forward and up are finite, up is not parallel to forward,
 * fov_y_deg is in [LOD_MIN_FOV_Y_DEG, LOD_MAX_FOV_Y_DEG], width and height are 1..65536 and
 * 0 < near_z < far_z with far_z finite. Culling is exact over that whole range. */
typedef struct lod_view {
  float eye[3], forward[3], up[3];
  float fov_y_deg;
  uint32_t width, height;
  float near_z, far_z;
} lod_view;

typedef struct lod_frame_info {
  uint64_t index, tick;
  uint32_t objects, visible;
  uint64_t tris_selected, budget;
  int over_budget;
} lod_frame_info;

typedef struct lod_frame_entry {
  lod_object object;
  uint32_t level, from_level;
  float morph;
  uint32_t view_mask;
  lod_transform transform;
} lod_frame_entry;

typedef struct lod_object_options {
  float lod_bias;       /* tolerates pixel_error * 2^lod_bias */
  uint32_t min_level;   /* finest level allowed */
  uint32_t max_level;   /* coarsest level allowed (clamped to the chain) */
  float priority;       /* > 0; importance divided by it */
  int32_t forced_level; /* >= 0: always this level */
  int never_cull;       /* nonzero: visible to every view */
} lod_object_options;

/* A scene TOML; [[model]]/[[instances]] optional. NULL on error, with the message. Baked
 * models are cached in the config's [cache] dir, else $LOD_CACHE_DIR, else
 * $XDG_CACHE_HOME/lodkit, else $HOME/.cache/lodkit, else a folder in the temp directory.
 * Files are read only when they are regular files: a FIFO, device, socket or directory given
 * as the config, a mesh, an asset or a file a mesh names (an OBJ's .mtl, a texture, a glTF
 * buffer) is refused by name without being opened ("f.off: is a FIFO, not a regular file").
 * A config is at most 16 MiB, a .mtl 16 MiB, a texture 256 MiB, a .gltf/.glb 4 GiB - 1. */
lod_service* lod_service_create(const char* config_path, char* error, size_t error_size);
void lod_service_destroy(lod_service*);

/* A mesh (baked, cached) or a .lod asset; 0 = ok. Regular files only (see above). A file is
   checked from its first bytes before it is read or hashed whole: a .lod whose header and
   sections do not end where the file does, or a mesh whose head cannot be its format (a NUL
   byte in a text format, a binary STL or GLB declaring more than the file holds), is refused
   without reading the rest. */
int lod_model_add(lod_service*, const char* path, lod_model* out, char* error, size_t error_size);
uint32_t lod_model_level_count(lod_service*, lod_model);
uint64_t lod_model_level_triangles(lod_service*, lod_model, uint32_t level);

/* ---- Level geometry and materials, for a renderer ---------------------------------------
 * Zero-copy views into the service's own immutable arrays. Ownership: every pointer below is
 * the service's; never free or write through it. Lifetime: valid and unchanged until
 * lod_service_destroy (models are never removed or changed); arrays the baked model does not
 * store in this layout (submesh runs, materials, texture paths) are built once per model by
 * lod_model_add. Threads: safe from any thread, concurrently with frames and object calls,
 * once lod_model_add has returned. Errors: a NULL service or out pointer, an unknown model, a
 * level >= lod_model_level_count or a material index >= lod_model_material_count gives a
 * nonzero return, *out untouched, and a message naming the value in lod_last_error(). */

/* Indices [first_index, first_index + index_count) of a level (level-local: 0 is the level's
 * first index), whole triangles, drawn with material `material` (-1: the default surface, the
 * glTF defaults lod_material lists). */
typedef struct lod_submesh {
  uint32_t first_index, index_count;
  int32_t material; /* -1: default surface */
} lod_submesh;

/* One level of a model, in the model's object space (the source file's units). Arrays with
 * nothing to hold (the culled level: 0 triangles) are NULL with counts 0. */
typedef struct lod_mesh {
  uint64_t id;                        /* nonzero; one id names the same bytes for the service's lifetime
                                         (unique per model and level within a service) */
  uint32_t vertex_count, index_count; /* 3 indices per triangle, counter-clockwise front faces (the
                                         source's winding; glTF, OBJ, PLY, OFF, STL all say CCW);
                                         index_count / 3 == lod_model_level_triangles */
  const float* positions;             /* 3 per vertex: x y z */
  const float* normals;               /* 3 per vertex, unit length (a source's zero normal stays
                                         zero), or NULL */
  const float* uvs;                   /* 2 per vertex (TEXCOORD_0, glTF convention: origin top left), or NULL */
  const float* colors;                /* 4 per vertex, linear RGBA, or NULL */
  const float* morph_positions;       /* 3 per vertex: the vertex at morph = 1, or NULL (no blend);
                                         always NULL for level meshes */
  const uint32_t* indices;            /* each < vertex_count */
  uint32_t submesh_count;             /* 0: one surface with the default material */
  const lod_submesh* submeshes;       /* cover the indices in order, without gaps, grouped by material */
} lod_mesh;

/* A texture: a file (`path`, absolute: the source's folder at bake time joined with the file
 * it named; NUL-terminated, not checked to exist) or an image the source held in itself (a GLB
 * buffer view or data: URI): its encoded `bytes` (`size` of them) and `mime` ("image/png" or
 * "image/jpeg"). A texture the source named by URL ("https://...") is not kept: none. `texcoord`: the uv set it reads (0: lod_mesh.uvs,
 * TEXCOORD_0; 1: TEXCOORD_1, which only the C++ API's LevelMeshView::uvs1 carries). */
typedef struct lod_texture {
  const char* path;
  const uint8_t* bytes;
  size_t size;
  const char* mime;
  uint32_t texcoord;
} lod_texture; /* all NULL/0: none */

/* glTF 2.0's metallic-roughness material as the bake read it (from glTF, or OBJ/MTL: Kd is
 * base_color, map_Kd its texture). What the source did not give has glTF's default: base_color
 * 1,1,1,1; metallic 1; roughness 1; emissive 0,0,0; alpha_mode opaque; alpha_cutoff 0.5;
 * single-sided; no textures. Factors are linear, each in [0, 1]. */
typedef struct lod_material {
  float base_color[4];  /* linear RGBA factor */
  float metallic, roughness;
  float emissive[3];    /* linear RGB factor */
  int alpha_mode;       /* 0 opaque, 1 mask, 2 blend */
  float alpha_cutoff;   /* used with mask */
  int double_sided;     /* nonzero: back faces drawn too */
  lod_texture base_color_texture;         /* sRGB colour, multiplied by base_color */
  lod_texture metallic_roughness_texture; /* roughness in G, metalness in B */
  lod_texture normal_texture;             /* tangent-space normals */
  lod_texture occlusion_texture;          /* ambient occlusion in R */
  lod_texture emissive_texture;           /* sRGB emitted colour */
} lod_material;

/* Level `level` (0 = full detail) of `model` into *out; 0 = ok. Valid while the service lives. */
int lod_model_level_mesh(lod_service*, lod_model, uint32_t level, lod_mesh* out);
/* The materials lod_submesh.material indexes; 0 for a model without materials (one default
 * surface), and 0 with a message for a NULL service or unknown model. */
uint32_t lod_model_material_count(lod_service*, lod_model);
/* Material `index` of `model` into *out; 0 = ok. Strings and bytes valid while the service lives. */
int lod_model_material(lod_service*, lod_model, uint32_t index, lod_material* out);

lod_object lod_object_create(lod_service*, lod_model, const lod_transform*); /* 0 on error */
int lod_object_destroy(lod_service*, lod_object);                            /* nonzero: stale or unknown */
int lod_object_set_transform(lod_service*, lod_object, const lod_transform*); /* nonzero: stale or unknown */
void lod_object_options_default(lod_object_options* out);
int lod_object_set_options(lod_service*, lod_object, const lod_object_options*); /* nonzero: stale, unknown, bad */
/* Publishes what was staged under `tick`; 0 = ok. Ticks never decrease: a tick below the last
 * committed one (a config's instances are committed at 0) is refused, nonzero with the message
 * in lod_last_error(), and the staged changes stay staged for the next commit. */
int lod_commit(lod_service*, uint64_t tick);

int lod_set_view(lod_service*, uint32_t view_index, const lod_view*); /* nonzero: index >= 8 or a bad view */
int lod_set_view_count(lod_service*, uint32_t count);                 /* 1..8 */
/* 0 = ok; nonzero (lod_last_error() says why) for a value outside the ranges above. */
int lod_set_budget(lod_service*, uint64_t triangles);  /* >= LOD_MIN_BUDGET */
int lod_set_pixel_error(lod_service*, float pixels);   /* (0, LOD_MAX_PIXEL_ERROR] */
int lod_set_hysteresis(lod_service*, float band);      /* [0, LOD_MAX_HYSTERESIS] */
int lod_set_blend_seconds(lod_service*, float seconds); /* [0, LOD_MAX_BLEND_SECONDS] */

int lod_start(lod_service*); /* free-running LOD thread at [run] rate_hz; 0 = ok */
void lod_stop(lod_service*);
int lod_step(lod_service*, double dt_seconds); /* driven mode: one frame on the caller's thread; 0 = ok */

const lod_frame* lod_frame_acquire(lod_service*); /* newest complete frame (NULL before the first), held until released */
void lod_frame_release(lod_service*, const lod_frame*);
void lod_frame_info_get(const lod_frame*, lod_frame_info*); /* objects = live objects at the frame's tick; visible = entries */
int lod_frame_entry_get(const lod_frame*, uint32_t i, lod_frame_entry*); /* i < visible; transform exactly as the caller set it */

/* The calling thread's last error message ("" when none). */
const char* lod_last_error(void);

#ifdef __cplusplus
}
#endif
#endif /* LODKIT_LODKIT_H */
