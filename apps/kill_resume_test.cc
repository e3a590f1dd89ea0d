// Kill anywhere, lose nothing (issue 25): `u4d run` killed with SIGKILL at
// random moments and then run again with the same command ends with the
// files of a run that was never interrupted (all but run.json, which holds
// times). The moments are drawn from a seed printed by the test;
// U4D_KILL_SEED=<seed> repeats them.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "u4d/util/testing.h"

extern char** environ;

namespace u4d {
namespace {

// Starts the u4d binary with `args`, its output to /dev/null.
pid_t Start(const std::vector<std::string>& args) {
  std::vector<std::string> all = {U4D_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, U4D_BINARY, &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  EXPECT_EQ(rc, 0) << "cannot start " << U4D_BINARY;
  return pid;
}

int WaitFor(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Runs u4d to its end; returns the seconds it took.
double RunToEnd(const std::vector<std::string>& args) {
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(WaitFor(Start(args)), 0) << "u4d " << args.front() << " failed";
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::map<std::string, std::string> SceneFiles(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename() != "run.json")
      files[e.path().lexically_relative(dir).generic_string()] = ReadTextFile(e.path());
  return files;
}

std::vector<std::string> Names(const std::map<std::string, std::string>& files) {
  std::vector<std::string> names;
  for (const auto& [name, bytes] : files) names.push_back(name);
  return names;
}

TEST(KillResume, AKilledRunResumesToTheSceneOfAnUninterruptedOne) {
  const fs::path dir = test_util::FreshTestDir("kill_resume", "runs");
  const std::string cap = (dir / "cap").string();
  RunToEnd({"synth", "-o", cap, "--views", "3", "--width", "160", "--height", "90", "--frames", "3",
            "--no-meshes"});
  const auto run_args = [&](const fs::path& scene) {
    return std::vector<std::string>{"run",
                                    cap,
                                    "-o",
                                    scene.string(),
                                    "--no-eval",
                                    "--no-progress",
                                    "--rounds",
                                    "1",
                                    "--working-width",
                                    "96",
                                    "--picture-width",
                                    "80"};
  };
  const fs::path reference = dir / "reference";
  const double seconds = RunToEnd(run_args(reference));
  const auto expected = SceneFiles(reference);

  const char* env_seed = std::getenv("U4D_KILL_SEED");
  const unsigned seed = env_seed ? std::stoul(env_seed) : std::random_device{}();
  std::printf("[kill_resume] seed %u (U4D_KILL_SEED repeats it); an uninterrupted run: %.2f s\n",
              seed, seconds);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> moment(0.02, 0.98);
  for (int k = 0; k < 5; ++k) {
    const fs::path scene = dir / ("killed" + std::to_string(k));
    // Up to two kills before the run that completes.
    for (int kill = 0; kill < 1 + k % 2; ++kill) {
      const double at = moment(rng) * seconds;
      const pid_t pid = Start(run_args(scene));
      std::this_thread::sleep_for(std::chrono::duration<double>(at));
      ::kill(pid, SIGKILL);
      WaitFor(pid);
      std::printf("[kill_resume] run %d killed after %.2f s\n", k, at);
    }
    RunToEnd(run_args(scene));
    const auto got = SceneFiles(scene);
    ASSERT_EQ(Names(got), Names(expected)) << "run " << k;
    for (const auto& [name, bytes] : expected)
      EXPECT_TRUE(got.at(name) == bytes) << "run " << k << ": " << name << " differs";
  }
}

}  // namespace
}  // namespace u4d
