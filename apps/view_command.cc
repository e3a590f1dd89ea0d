// `u4d view <scene> [--port N]`: serves the web viewer (viewer/, built into
// viewer/dist by the CMake target `viewer`) and the scene over HTTP on
// 127.0.0.1 and prints the address. The page loads the scene from scene/
// relative to itself, so the server maps / to the viewer bundle and /scene/
// to the scene directory.
// `u4d export-viewer <scene> -o <folder>`: the same as a folder (the bundle
// plus <folder>/scene/) that any static web server can host.
// docs/viewer.md describes both.
#include <csignal>
#include <cstdlib>
#include <memory>

#include <fmt/format.h>
#include <unistd.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "u4d/io/layout.h"
#include "u4d/io/output_dir.h"
#include "u4d/io/scene_index.h"
#include "u4d/util/check.h"
#include "u4d/util/file.h"

// Last: httplib.h defines macros that clash with Eigen's templates.
#include <httplib.h>

#ifndef U4D_VIEWER_DIST
#define U4D_VIEWER_DIST ""
#endif

namespace u4d::apps {
namespace {

// The built viewer: --viewer-dir, else $U4D_VIEWER_DIST, else viewer/ next to
// the binary (an installed layout), else the source tree's viewer/dist.
fs::path FindViewer(const std::string& given) {
  std::vector<fs::path> candidates;
  if (!given.empty()) {
    U4D_CHECK(
        fs::exists(fs::path(given) / "index.html") && fs::exists(fs::path(given) / "viewer.js"),
        "--viewer-dir {}: expected the built viewer (index.html and viewer.js) there", given);
    return given;
  }
  if (const char* env = std::getenv("U4D_VIEWER_DIST")) candidates.push_back(env);
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path() / "viewer");
  candidates.push_back(U4D_VIEWER_DIST);
  for (const fs::path& c : candidates)
    if (!c.empty() && fs::exists(c / "index.html") && fs::exists(c / "viewer.js")) return c;
  std::string tried;
  for (const fs::path& c : candidates) tried += "\n  " + c.string();
  ThrowError(fmt::format(
      "the web viewer is not built (no index.html + viewer.js in any of:{}); build it with "
      "`ninja viewer` (needs npm) or pass --viewer-dir",
      tried));
}

struct ViewArgs {
  std::string scene;
  int port = 8080;
  std::string viewer_dir;
};

int RunView(const ViewArgs& a) {
  const fs::path scene = fs::absolute(a.scene);
  ReadSceneIndex(scene);  // fails early, naming the problem, on a bad scene
  const fs::path viewer = FindViewer(a.viewer_dir);
  httplib::Server server;
  // cpp-httplib's default sets SO_REUSEPORT too, which lets a second server
  // share a busy port (requests then alternate between two scenes); only
  // SO_REUSEADDR (restart without waiting for TIME_WAIT) is wanted.
  server.set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, reinterpret_cast<const void*>(&yes), sizeof(yes));
  });
  U4D_CHECK(server.set_mount_point("/scene", scene.string()), "cannot serve {}", scene.string());
  U4D_CHECK(server.set_mount_point("/", viewer.string()), "cannot serve {}", viewer.string());
  server.set_file_extension_and_mimetype_mapping("ply", "application/octet-stream");
  server.set_file_extension_and_mimetype_mapping("glb", "model/gltf-binary");
  server.set_file_extension_and_mimetype_mapping("json", "application/json");
  int port = a.port;
  if (port == 0) {
    port = server.bind_to_any_port("127.0.0.1");
    U4D_CHECK(port > 0, "cannot bind a port on 127.0.0.1");
  } else {
    U4D_CHECK(server.bind_to_port("127.0.0.1", port),
              "cannot listen on 127.0.0.1:{}: the port is in use (another `u4d view`?) or "
              "not allowed; pick another with --port, or --port 0 for any free one",
              port);
  }
  fmt::print("serving {} at http://127.0.0.1:{}/ (Ctrl-C to stop)\n", scene.string(), port);
  std::fflush(stdout);
  U4D_CHECK(server.listen_after_bind(), "the server on port {} stopped with an error", port);
  return 0;
}

// fs::copy (recursive, overwriting) with a u4d::Error naming both paths.
void CopyOrThrow(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::copy(from, to, fs::copy_options::recursive | fs::copy_options::overwrite_existing, ec);
  U4D_CHECK(!ec, "u4d export-viewer: cannot copy {} to {}: {}", from.string(), to.string(),
            ec.message());
}

struct ExportArgs {
  std::string scene;
  std::string out;
  std::string viewer_dir;
  bool all = false;
};

// What the page reads: the index, calibration, evaluation, key-frames and
// the viewer's own folders. The raw maps (instances/, depth/, flow/) are left
// out unless --all.
int RunExport(const ExportArgs& a) {
  const fs::path scene = a.scene;
  const SceneIndex index = ReadSceneIndex(scene);
  const fs::path viewer = FindViewer(a.viewer_dir);
  const fs::path out = a.out;
  OutputDirOptions out_dir;
  out_dir.command = "u4d export-viewer";
  out_dir.inputs = {scene, viewer};
  out_dir.markers = {"index.html"};
  CheckOutputDir(out, out_dir);
  for (const auto& entry : fs::directory_iterator(viewer))
    CopyOrThrow(entry.path(), out / entry.path().filename());
  const fs::path dest = out / "scene";
  CreateDirectories(dest);
  const std::vector<std::string> read_by_viewer = {layout::SceneIndex().string(),
                                                   layout::SceneCalibration().string(),
                                                   layout::SceneEval().string(),
                                                   layout::SceneKeyframes().string(),
                                                   "pictures",
                                                   "meshes",
                                                   "poses3d",
                                                   "tracks",
                                                   "segments"};
  int64_t bytes = 0;
  for (const auto& entry : fs::directory_iterator(scene)) {
    const std::string name = entry.path().filename().string();
    if (!a.all &&
        std::find(read_by_viewer.begin(), read_by_viewer.end(), name) == read_by_viewer.end())
      continue;
    CopyOrThrow(entry.path(), dest / name);
  }
  for (const auto& e : fs::recursive_directory_iterator(out))
    if (e.is_regular_file()) bytes += static_cast<int64_t>(e.file_size());
  fmt::print(
      "wrote the viewer of {} ({} frames) to {} ({:.1f} MB)\n"
      "open it through any static web server, e.g. `python3 -m http.server -d {}`; browsers\n"
      "refuse fetch() on file:// pages, so opening index.html directly does not work\n",
      index.name, index.frames.size(), out.string(), bytes / 1e6, out.string());
  return 0;
}

}  // namespace

Command MakeViewCommand() {
  auto a = std::make_shared<ViewArgs>();
  return {"view", "serve the web viewer of a 4D scene on 127.0.0.1 and print its address",
          [=](CLI::App& app) {
            app.add_option("scene", a->scene, "scene directory (output of u4d run)")->required();
            app.add_option("--port", a->port, "TCP port, 1-65535 (0 = any free port)")
                ->check(CLI::Range(0, 65535))
                ->capture_default_str();
            app.add_option("--viewer-dir", a->viewer_dir, "the built viewer (viewer/dist)");
          },
          [=] { return RunView(*a); }};
}

Command MakeExportViewerCommand() {
  auto a = std::make_shared<ExportArgs>();
  return {"export-viewer", "write a self-contained folder: the web viewer and the scene",
          [=](CLI::App& app) {
            app.add_option("scene", a->scene, "scene directory (output of u4d run)")->required();
            app.add_option("-o,--output", a->out, "folder to write")->required();
            app.add_option("--viewer-dir", a->viewer_dir, "the built viewer (viewer/dist)");
            app.add_flag("--all", a->all, "also copy the raw maps (instances, depth, flow)");
          },
          [=] { return RunExport(*a); }};
}

}  // namespace u4d::apps
