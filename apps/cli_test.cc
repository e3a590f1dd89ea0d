// The `u4d` command on bad input (issue 25): each case runs the built binary
// and checks the exit status and that the message names the flag or file and
// the problem. Exit 1 is a u4d::Error; CLI11 rejects bad option values with
// its own status; nothing here may end in a signal or "internal error".
#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include "u4d/io/capture.h"
#include "u4d/io/scene_index.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

struct Result {
  int status = -1;  // exit status; -1 when killed by a signal
  std::string output;
};

std::string Quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

Result RunU4d(const std::vector<std::string>& args) {
  // Bounded, so that a regression (e.g. a server that does start) fails
  // with status 124 instead of hanging the test.
  std::string cmd = "timeout 120 " + Quote(U4D_BINARY);
  for (const std::string& a : args) {
    cmd += ' ';  // not `" " + Quote(a)`: GCC 12's false -Wrestrict (bug 105329)
    cmd += Quote(a);
  }
  cmd += " 2>&1";
  Result r;
  FILE* pipe = ::popen(cmd.c_str(), "r");
  EXPECT_NE(pipe, nullptr);
  std::array<char, 4096> buf;
  size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) r.output.append(buf.data(), n);
  const int st = ::pclose(pipe);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

// Expects a clean failure: the given status and a message with every part.
void ExpectFails(const std::vector<std::string>& args, int status,
                 const std::vector<std::string>& parts) {
  const Result r = RunU4d(args);
  std::string line;
  for (const std::string& a : args) line += " " + a;
  EXPECT_EQ(r.status, status) << "u4d" << line << "\n" << r.output;
  EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
  for (const std::string& p : parts)
    EXPECT_NE(r.output.find(p), std::string::npos)
        << "u4d" << line << ": output does not mention '" << p << "':\n"
        << r.output;
}

// CLI11's exit status for a value that fails a ->check() validator.
constexpr int kCliValidation = 105;

Capture OneViewCapture() {
  Capture c;
  c.name = "tiny";
  c.num_frames = 1;
  CaptureView view;
  view.name = "cam0";
  Camera cam;
  cam.width = 8;
  cam.height = 6;
  cam.K << 10, 0, 4, 0, 10, 3, 0, 0, 1;
  view.cameras = {cam};
  view.source.path = "images/cam0/{:06d}.png";
  c.views.push_back(view);
  return c;
}

TEST(Cli, OptionValuesOutOfRangeNameTheFlag) {
  const fs::path dir = test_util::FreshTestDir("cli", "ranges");
  const std::string out = (dir / "cap").string();
  ExpectFails({"synth", "-o", out, "--views", "0"}, kCliValidation, {"--views", "0"});
  ExpectFails({"synth", "-o", out, "--width", "-5"}, kCliValidation, {"--width"});
  ExpectFails({"synth", "-o", out, "--frames", "-3"}, kCliValidation, {"--frames"});
  ExpectFails({"synth", "-o", out, "--height", "0"}, kCliValidation, {"--height"});
  ExpectFails({"run", (dir / "c").string(), "-o", out, "--rounds", "1000"}, kCliValidation,
              {"--rounds", "1000"});
  ExpectFails({"run", (dir / "c").string(), "-o", out, "--rounds", "0"}, kCliValidation,
              {"--rounds"});
  ExpectFails({"view", (dir / "s").string(), "--port", "70000"}, kCliValidation,
              {"--port", "70000"});
  ExpectFails({"view", (dir / "s").string(), "--port", "-1"}, kCliValidation, {"--port"});
  EXPECT_FALSE(fs::exists(out));  // nothing was written
}

TEST(Cli, BadCaptureJsonIsAnErrorNamingTheFile) {
  const fs::path cap = test_util::FreshTestDir("cli", "bad_capture");
  WriteCapture(OneViewCapture(), cap);
  nlohmann::json m = ReadJsonFile(cap / "capture.json");
  m["views"][0]["path"] = "images/cam0/{:06q}.png";
  WriteJsonFileAtomic(cap / "capture.json", m);
  ExpectFails({"info", cap.string()}, 1,
              {"u4d info: error:", "capture.json", "view cam0", "invalid path pattern"});
  WriteTextFileAtomic(cap / "capture.json", "[1, 2]");
  ExpectFails({"info", cap.string()}, 1, {"capture.json", "expected a JSON object"});
  WriteTextFileAtomic(cap / "capture.json", "{\"fps\": 1e999}");
  ExpectFails({"info", cap.string()}, 1, {"capture.json", "invalid JSON"});
}

TEST(Cli, OutputFoldersAreCheckedBeforeAnyWork) {
  const fs::path dir = test_util::FreshTestDir("cli", "outputs");
  const fs::path cap = dir / "cap";
  WriteCapture(OneViewCapture(), cap);
  // The capture itself as the scene folder.
  ExpectFails({"run", cap.string(), "-o", cap.string(), "--no-progress"}, 1,
              {"u4d run --output", "is the input"});
  // A regular file in the way.
  WriteTextFileAtomic(dir / "blocker", "x");
  ExpectFails({"run", cap.string(), "-o", (dir / "blocker" / "scene").string(), "--no-progress"}, 1,
              {"u4d run --output", "blocker/scene", "cannot"});
  ExpectFails({"synth", "-o", (dir / "blocker").string(), "--frames", "1"}, 1,
              {"u4d synth --output", "blocker", "not a directory"});
  // A non-empty folder that is not a previous scene / capture.
  WriteTextFileAtomic(dir / "mine" / "notes.txt", "keep me");
  ExpectFails({"run", cap.string(), "-o", (dir / "mine").string(), "--no-progress"}, 1,
              {"u4d run --output", "not empty", "run.json"});
  ExpectFails({"synth", "-o", (dir / "mine").string(), "--frames", "1"}, 1,
              {"u4d synth --output", "not empty", "--force"});
  EXPECT_EQ(ReadTextFile(dir / "mine" / "notes.txt"), "keep me");
}

// --config, --set and the named flags reach any option, in that order of
// precedence; params.json (written before the frames are read, which this
// capture lacks) records what the run used.
TEST(Cli, RunConfigSetAndFlagsOverrideAnyOption) {
  const fs::path dir = test_util::FreshTestDir("cli", "config");
  const fs::path cap = dir / "cap";
  WriteCapture(OneViewCapture(), cap);
  const fs::path config = dir / "config.json";
  WriteJsonFileAtomic(config, {{"paper_weights", false},
                               {"joint", {{"rounds", 3}, {"weights", {{"flow", 0.6}}}}},
                               {"init", {{"foreground", {{"threshold_sigmas", 5.5}}}}},
                               {"frame_setup", {{"working_width", 200}}}});
  const fs::path scene = dir / "scene";
  RunU4d({"run", cap.string(), "-o", scene.string(), "--no-progress", "--config", config.string(),
          "--set", "frame_setup.working_width=160", "--set", "init.people.box_fill=always",
          "--rounds", "4"});
  const nlohmann::json p = ReadJsonFile(scene / "params.json");
  EXPECT_EQ(p["joint"]["rounds"], 4);
  EXPECT_EQ(p["joint"]["weights"]["flow"], 0.6);
  EXPECT_EQ(p["paper_weights"], false);
  EXPECT_EQ(p["init"]["foreground"]["threshold_sigmas"], 5.5);
  EXPECT_EQ(p["init"]["people"]["box_fill"], "always");
  EXPECT_EQ(p["frame_setup"]["working_width"], 160);
  EXPECT_EQ(p["progress"], false);

  // The earlier format: top-level weights replace the paper's table.
  WriteJsonFileAtomic(config, {{"weights", {{"flow", 0.7}}}});
  RunU4d({"run", cap.string(), "-o", (dir / "legacy").string(), "--no-progress", "--config",
          config.string()});
  const nlohmann::json legacy = ReadJsonFile(dir / "legacy" / "params.json");
  EXPECT_EQ(legacy["joint"]["weights"]["flow"], 0.7);
  EXPECT_EQ(legacy["paper_weights"], false);

  const std::string out = (dir / "bad").string();
  WriteJsonFileAtomic(config, {{"joint", {{"rouds", 3}}}});
  ExpectFails({"run", cap.string(), "-o", out, "--config", config.string()}, 1,
              {"config.json", "unknown option 'joint.rouds'"});
  ExpectFails({"run", cap.string(), "-o", out, "--set", "joint.rounds=two"}, 1,
              {"--set", "'joint.rounds'", "'two'"});
  ExpectFails({"run", cap.string(), "-o", out, "--set", "joint.weights.flow=0.6"}, 1,
              {"joint.weights", "paper_weights"});
  ExpectFails({"run", cap.string(), "-o", out, "--box-fill", "sometimes"}, kCliValidation,
              {"--box-fill", "never, empty-views, always", "sometimes"});
  ExpectFails({"run", cap.string(), "-o", out, "--chroma-key", "sometimes"}, kCliValidation,
              {"--chroma-key", "off, auto, on", "sometimes"});
  ExpectFails({"run", cap.string(), "-o", out, "--set", "chroma_key.colour=greenish"}, 1,
              {"colour", "greenish"});
  EXPECT_FALSE(fs::exists(out));
}

// synth into a previous capture: refused without --force; with it, the old
// capture is replaced, so no view of it is left beside the new ones.
TEST(Cli, SynthForceReplacesAPreviousCapture) {
  const fs::path dir = test_util::FreshTestDir("cli", "synth_force");
  const std::string out = (dir / "cap").string();
  const std::vector<std::string> tiny = {"synth",   "-o", out,        "--frames", "2",
                                         "--width", "32", "--height", "24",       "--no-meshes"};
  std::vector<std::string> three = tiny;
  three.insert(three.end(), {"--views", "3"});
  const Result first = RunU4d(three);
  ASSERT_EQ(first.status, 0) << first.output;
  ASSERT_TRUE(fs::exists(dir / "cap" / "images" / "cam02"));
  std::vector<std::string> two = tiny;
  two.insert(two.end(), {"--views", "2"});
  ExpectFails(two, 1, {"u4d synth --output", "not empty", "--force"});
  two.push_back("--force");
  const Result second = RunU4d(two);
  ASSERT_EQ(second.status, 0) << second.output;
  EXPECT_EQ(ReadCapture(dir / "cap").NumViews(), 2);
  EXPECT_FALSE(fs::exists(dir / "cap" / "images" / "cam02"));
}

// dir/scene: a one-frame scene index; dir/viewer: a stand-in for the viewer's files.
void WriteTinySceneAndViewer(const fs::path& dir) {
  SceneIndex index;
  index.name = "tiny";
  index.frames = {0};
  index.views = {{"cam0", 8, 6}};
  WriteSceneIndex(dir / "scene", index);
  WriteTextFileAtomic(dir / "viewer" / "index.html", "<html></html>");
  WriteTextFileAtomic(dir / "viewer" / "viewer.js", "");
}

TEST(Cli, ExportViewerIntoTheSceneIsRefused) {
  const fs::path dir = test_util::FreshTestDir("cli", "export");
  WriteTinySceneAndViewer(dir);
  ExpectFails({"export-viewer", (dir / "scene").string(), "-o", (dir / "scene" / "site").string(),
               "--viewer-dir", (dir / "viewer").string()},
              1, {"u4d export-viewer --output", "inside it"});
  const Result ok = RunU4d({"export-viewer", (dir / "scene").string(), "-o",
                            (dir / "site").string(), "--viewer-dir", (dir / "viewer").string()});
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_TRUE(fs::exists(dir / "site" / "scene" / "scene.json"));
}

// A listening socket on 127.0.0.1 at a free port; closed on destruction.
class BusyPort {
 public:
  BusyPort() {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    int yes = 1;
    ::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
    ::setsockopt(fd_, SOL_SOCKET, SO_REUSEPORT, &yes, sizeof(yes));  // as an old u4d view did
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    EXPECT_EQ(::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
    EXPECT_EQ(::listen(fd_, 4), 0);
    socklen_t len = sizeof(a);
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
  }
  ~BusyPort() { ::close(fd_); }
  int port() const { return port_; }

 private:
  int fd_ = -1;
  int port_ = 0;
};

TEST(Cli, ViewOnABusyPortFails) {
  const fs::path dir = test_util::FreshTestDir("cli", "view");
  WriteTinySceneAndViewer(dir);
  const BusyPort busy;
  ExpectFails({"view", (dir / "scene").string(), "--port", std::to_string(busy.port()),
               "--viewer-dir", (dir / "viewer").string()},
              1, {"u4d view: error:", std::to_string(busy.port()), "in use"});
}

}  // namespace
}  // namespace u4d
