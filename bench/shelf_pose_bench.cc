// Shelf multi-person 3D pose: per-actor, per-limb PCP (alpha 0.5) of the
// pose module's pipeline (testing/shelf.h) against gt.txt, the literature's
// protocol (each GT actor is matched to its nearest predicted person).
// Usage: shelf_pose_bench [shelf_dir] [--json FILE]   (default /work/shared/data/shelf_pose)
#include <cstdio>
#include <map>
#include <string>
#include <utility>

#include <fmt/core.h>

#include "bench_table.h"
#include "u4d/eval/pose_metrics.h"
#include "u4d/io/import_fourda.h"
#include "u4d/testing/shelf.h"
#include "u4d/util/check.h"
#include "u4d/util/timer.h"

namespace {

std::vector<u4d::eval::Person3d> ToShelf14(const std::vector<u4d::Pose3d>& poses) {
  std::vector<u4d::eval::Person3d> out;
  for (const u4d::Pose3d& p : poses) {
    const auto j = u4d::Shelf14FromH36m17(p);
    u4d::eval::Person3d q;
    q.id = p.person_id;
    for (const Eigen::Vector4d& x : j) {
      q.joints.push_back(x.head<3>());
      q.confidence.push_back(x.w());
    }
    out.push_back(q);
  }
  return out;
}

// A row of PCP rates (%) per actor and their mean over actors 1-3, printed and kept;
// rates: (actor id, rate) in the order of the actors.
void PcpRow(const std::string& name, const std::vector<std::pair<int, double>>& rates,
            u4d::bench::Table* table) {
  fmt::print("{:<12}", name);
  std::vector<std::string> cells = {name};
  double sum = 0;
  for (const auto& [id, r] : rates) {
    fmt::print(" {:>11.1f}", r);
    cells.push_back(fmt::format("{:.1f}", r));
    if (id < 3) sum += r;
  }
  fmt::print(" {:>8.1f}\n", sum / 3);
  cells.push_back(fmt::format("{:.1f}", sum / 3));
  table->Row(cells);
}

void Report(const char* title, const std::vector<std::vector<u4d::Pose3d>>& pred,
            const u4d::FourdaGroundTruth& gt, u4d::bench::BenchTables* tables) {
  const auto limbs = u4d::eval::Shelf14Limbs();
  const u4d::eval::PoseOptions options;
  std::map<int, u4d::eval::PoseMetrics> per_actor;
  const size_t frames = std::min(pred.size(), gt.frames.size());
  for (size_t f = 0; f < frames; ++f) {
    const auto p = ToShelf14(pred[f]);
    for (const u4d::FourdaPerson3d& g : gt.frames[f]) {
      u4d::eval::Person3d q;
      q.id = g.id;
      for (int j = 0; j < 14; ++j) {
        q.joints.push_back(g.joints.col(j).head<3>());
        q.confidence.push_back(g.joints(3, j));
      }
      per_actor[g.id].Add(u4d::eval::EvaluatePoses(p, {q}, limbs, options, "shelf"));
    }
  }
  fmt::print("\n{}\n{:<12}", title, "limb");
  for (const auto& [id, m] : per_actor) fmt::print(" actor{}({:>3})", id + 1, m.frames);
  fmt::print(" avg(1-3)\n");
  std::vector<std::string> columns = {"limb"};
  for (const auto& [id, m] : per_actor) columns.push_back(fmt::format("actor{}", id + 1));
  columns.push_back("avg(1-3)");
  u4d::bench::Table& table = tables->Record(title, columns);
  std::vector<std::string> names;
  for (const auto& [name, c] : per_actor.begin()->second.pcp_per_limb) names.push_back(name);
  std::map<int, double> actor_avg;
  for (const std::string& name : names) {
    std::vector<std::pair<int, double>> rates;
    for (const auto& [id, m] : per_actor)
      rates.emplace_back(id, 100 * m.pcp_per_limb.at(name).Rate());
    PcpRow(name, rates, &table);
  }
  std::vector<std::pair<int, double>> all;
  for (const auto& [id, m] : per_actor) all.emplace_back(id, 100 * m.pcp.Rate());
  PcpRow("all", all, &table);
  double mpjpe_sum = 0;
  for (const auto& [id, m] : per_actor)
    if (id < 3) mpjpe_sum += m.Mpjpe();
  fmt::print("MPJPE (14 Shelf joints, actors 1-3 mean): {:.1f} mm\n", 1000 * mpjpe_sum / 3);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    u4d::bench::BenchTables tables("shelf_pose_bench", u4d::bench::TakeJsonFlag(&argc, argv));
    const u4d::fs::path dir = argc > 1 ? argv[1] : "/work/shared/data/shelf_pose";
    const u4d::FourdaGroundTruth gt = u4d::ReadFourdaGroundTruth(dir / "gt.txt");
    u4d::Timer timer;
    const u4d::ShelfPipelineResult result = u4d::RunShelfPipeline(dir);
    const double seconds = timer.Seconds();
    fmt::print(
        "Shelf: {} frames in {:.2f} s ({:.1f} ms/frame, 5 views: 2D assembly + "
        "association + triangulation + tracking)\n",
        result.raw.size(), seconds, 1000 * seconds / result.raw.size());
    Report("PCP (%), raw triangulation", result.raw, gt, &tables);
    Report("PCP (%), tracked + smoothed", result.tracked, gt, &tables);
    tables.Write();
    return 0;
  } catch (const u4d::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
