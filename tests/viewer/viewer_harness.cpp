#include "viewer/viewer_harness.h"

#include <cstdlib>
#include <fstream>
#include <map>
#include <stdexcept>
#include <sstream>
#include <tuple>

#include <stb_image.h>

#include "test_support.h"

namespace lod::test {

std::string front_camera(int width, int height) {
  return "[camera]\nfov_deg = 60\nwidth = " + std::to_string(width) + "\nheight = " + std::to_string(height) +
         "\npath = \"keyframes\"\nnear = 0.5\nfar = 500.0\n[[camera.keyframe]]\nframe = 0\n"
         "position = [0.0, 0.0, 30.0]\nlook_at = [0.0, 0.0, 0.0]\n";
}

std::string one_object_at_origin(const std::string& model, float scale, int seed) {
  std::ostringstream s;
  s << "[[instances]]\nmodel = \"" << model << "\"\ncount = 1\nplacement = \"grid\"\nbox_min = [0.0, 0.0, 0.0]\n"
    << "box_max = [0.0, 0.0, 0.0]\nscale = " << std::to_string(scale) << "\n";
  if (seed >= 0) s << "seed = " << seed << "\n";
  return s.str();
}

std::string box_off(int n) {
  // Vertices on the cube's surface lattice, keyed by integer coordinates so that the faces
  // share their edge vertices (a closed, welded mesh).
  std::map<std::tuple<int, int, int>, int> index;
  std::vector<std::tuple<int, int, int>> verts;
  std::vector<int> tris;
  auto vertex = [&](int x, int y, int z) {
    auto key = std::make_tuple(x, y, z);
    auto [it, added] = index.emplace(key, int(verts.size()));
    if (added) verts.push_back(key);
    return it->second;
  };
  // Each face: axis a fixed at side s (0 or n), the other two axes u, v spanning the grid.
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side <= 1; ++side) {
      const int u = (a + 1) % 3, v = (a + 2) % 3;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          int q[4];
          const int corners[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
          for (int k = 0; k < 4; ++k) {
            int c[3];
            c[a] = side * n;
            c[u] = corners[k][0];
            c[v] = corners[k][1];
            q[k] = vertex(c[0], c[1], c[2]);
          }
          if (side == 1) {  // outward winding on both sides
            tris.insert(tris.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
          } else {
            tris.insert(tris.end(), {q[0], q[2], q[1], q[0], q[3], q[2]});
          }
        }
    }
  std::ostringstream s;
  s << "OFF\n" << verts.size() << " " << tris.size() / 3 << " 0\n";
  for (auto [x, y, z] : verts) s << 2.0 * x / n - 1 << " " << 2.0 * y / n - 1 << " " << 2.0 * z / n - 1 << "\n";
  for (size_t t = 0; t < tris.size(); t += 3) s << "3 " << tris[t] << " " << tris[t + 1] << " " << tris[t + 2] << "\n";
  return s.str();
}

ViewerScene write_viewer_scene(const std::string& tag, const std::string& budget_and_run, const std::string& camera,
                               const std::string& instances, const std::string& extra_models) {
  ViewerScene scene;
  scene.dir = temp_dir("viewer-" + tag);
  write_text(scene.dir / "sphere.off", sphere_off(25, 48));
  write_text(scene.dir / "box.off", box_off(16));
  std::ostringstream c;
  c << budget_and_run << "\n"
    << camera << "\n"
    << "[[model]]\nname = \"sphere\"\nfile = \"sphere.off\"\nratios = [1.0, 0.5, 0.25, 0.12, 0.06]\n\n"
    << "[[model]]\nname = \"box\"\nfile = \"box.off\"\nratios = [1.0, 0.5, 0.25, 0.12, 0.06]\n\n"
    << extra_models << "\n"
    << instances << "\n";
  scene.config = scene.dir / "config.toml";
  write_text(scene.config, c.str());
  return scene;
}

bool have_xvfb() { return std::system("command -v xvfb-run > /dev/null 2>&1") == 0; }

RunResult run_viewer(const ViewerScene& scene, const std::string& args, bool under_xvfb, const std::string& env_prefix) {
  const std::filesystem::path log = scene.dir / "viewer-output.txt";
  const std::filesystem::path rc = scene.dir / "viewer-exit-code.txt";
  std::filesystem::remove(rc);
  std::ostringstream viewer;
  viewer << env_prefix << " '" << LOD_VIEWER_BINARY << "' --config '" << scene.config.string() << "' --cache '"
         << (scene.dir / "cache").string() << "' --backdrop off " << args << " > '" << log.string() << "' 2>&1; echo $? > '"
         << rc.string() << "'";
  // The viewer's own exit code goes through a file: xvfb-run's can differ (it reports its
  // own clean-up trouble).
  std::string cmd = viewer.str();
  if (under_xvfb) {
    std::string quoted;
    for (char ch : cmd) quoted += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
    cmd = "xvfb-run -a -s '-screen 0 1280x1024x24' sh -c '" + quoted + "' > /dev/null 2>&1";
  }
  RunResult r;
  // No exit-code file means the viewer never ran (xvfb-run could not start a server, e.g. a
  // display number taken in between): try once more.
  for (int attempt = 0; attempt < 2 && !std::filesystem::exists(rc); ++attempt)
    if (std::system(cmd.c_str()) == -1) return r;  // no shell: exit_code stays -1
  std::ifstream code(rc);
  if (!(code >> r.exit_code)) r.exit_code = -1;
  std::ifstream f(log);
  r.output.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  return r;
}

bool load_png(const std::filesystem::path& path, Image& out) {
  int channels = 0;
  unsigned char* data = stbi_load(path.c_str(), &out.width, &out.height, &channels, 3);
  if (!data) return false;
  out.rgb.assign(data, data + size_t(out.width) * size_t(out.height) * 3);
  stbi_image_free(data);
  return true;
}

double CsvTable::get(size_t row, const std::string& column) const {
  for (size_t c = 0; c < columns.size(); ++c)
    if (columns[c] == column) return rows.at(row).at(c);
  throw std::out_of_range("no column " + column + " in the viewer's --stats CSV");
}

bool load_csv(const std::filesystem::path& path, CsvTable& out) {
  std::ifstream f(path);
  std::string line;
  if (!std::getline(f, line)) return false;
  std::stringstream header(line);
  for (std::string col; std::getline(header, col, ',');) out.columns.push_back(col);
  while (std::getline(f, line)) {
    std::stringstream s(line);
    std::vector<double> row;
    for (std::string cell; std::getline(s, cell, ',');) row.push_back(std::stod(cell));
    if (row.size() != out.columns.size()) return false;
    out.rows.push_back(std::move(row));
  }
  return true;
}

Screenshot take_screenshot(const ViewerScene& scene, const std::string& name, const std::string& args) {
  Screenshot shot;
  const std::filesystem::path png = scene.dir / (name + ".png"), csv = scene.dir / (name + ".csv");
  shot.run = run_viewer(scene, "--screenshot '" + png.string() + "' --stats '" + csv.string() + "' " + args);
  if (shot.run.exit_code != 0) return shot;
  shot.image_read = load_png(png, shot.image);
  shot.stats_read = load_csv(csv, shot.stats);
  return shot;
}

}  // namespace lod::test
