/* lodkit from C99: a service from a scene config, ten objects of its first model in a row,
 * one view, a few driven frames, one frame read, and the geometry a renderer would draw for
 * its first entry. Usage: c_minimal CONFIG.toml */
#include <inttypes.h>
#include <lodkit/lodkit.h>
#include <stdio.h>

int main(int argc, char** argv) {
  char error[512];
  if (argc != 2) return fprintf(stderr, "usage: %s CONFIG.toml\n", argv[0]), 2;
  lod_service* s = lod_service_create(argv[1], error, sizeof error);
  if (!s) return fprintf(stderr, "lod_service_create: %s\n", error), 1;
  int failed = lod_model_level_count(s, 0) == 0; /* the config must have a [[model]] */
  for (int i = 0; i < 10 && !failed; ++i) {
    lod_transform t = {{4.0f * (float)i, 0, 0}, {0, 0, 0, 1}, 1};
    failed = lod_object_create(s, 0, &t) == 0;
  }
  lod_commit(s, 1);
  lod_view view = {{18, 2, 30}, {0, 0, -1}, {0, 1, 0}, 60, 1280, 720, 0.1f, 1000};
  failed = failed || lod_set_view(s, 0, &view) != 0;
  for (int f = 0; f < 5 && !failed; ++f) failed = lod_step(s, 1.0 / 60) != 0;
  const lod_frame* frame = failed ? NULL : lod_frame_acquire(s);
  if (frame) {
    lod_frame_info info;
    lod_frame_info_get(frame, &info);
    printf("visible %" PRIu32 " tris %" PRIu64 "\n", info.visible, info.tris_selected);
    failed = info.tick != 1 || info.objects < 10; /* the frame shows the committed tick */
    lod_frame_entry entry;
    lod_mesh mesh;
    if (!failed && info.visible > 0) { /* the level's arrays, as lodkit holds them (no copy) */
      failed = lod_frame_entry_get(frame, 0, &entry) != 0 || lod_model_level_mesh(s, 0, entry.level, &mesh) != 0;
      if (!failed) {
        printf("entry 0: level %" PRIu32 ", %" PRIu32 " vertices, %" PRIu32 " triangles, %" PRIu32 " materials\n",
               entry.level, mesh.vertex_count, mesh.index_count / 3, lod_model_material_count(s, 0));
        failed = mesh.index_count / 3 != lod_model_level_triangles(s, 0, entry.level);
      }
    }
    lod_frame_release(s, frame);
  }
  if (failed || !frame) fprintf(stderr, "failed: %s\n", *lod_last_error() ? lod_last_error() : "no [[model]] in the config");
  lod_service_destroy(s);
  return failed || !frame;
}
