// Timing of the fusion module (docs/fusion.md), on the handshake (walking)
// and on the realistic world (captured performers; skipped without the shared
// data): FuseObject per object per frame at 8 views x 480x270 and 8 x
// 960x540, TrackVertices per step, and
// the vertex drift of a tracked 10-frame segment against the GT meshes;
// then, on the 480x270 frame, FuseObject per Poisson octree depth and
// thread count (time, vertices, Chamfer against the GT mesh).
// A plain executable that prints; run from a Release build:
//   build/bench/fusion_bench [--json FILE]
#include <algorithm>
#include <cstdio>

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>

#include "bench_table.h"
#include "bench_worlds.h"
#include "u4d/eval/mesh_metrics.h"
#include "u4d/fusion/depth_fusion.h"
#include "u4d/fusion/fusion_test_util.h"
#include "u4d/fusion/scene_flow.h"
#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/io/layout.h"
#include "u4d/synth/generate.h"
#include "u4d/util/stats.h"
#include "u4d/util/timer.h"

using namespace u4d;

namespace {

using Maps = fusion_test::FrameMaps;

std::vector<SceneFlowView> Step(const Maps& a, const Maps& b) {
  std::vector<SceneFlowView> out;
  for (size_t v = 0; v < a.cameras.size(); ++v)
    out.push_back(
        {a.cameras[v], b.cameras[v], a.depths[v], b.depths[v], a.flows[v], a.ids[v], b.ids[v]});
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  bench::BenchTables tables("fusion_bench", bench::TakeJsonFlag(&argc, argv));
  bench::Table& fused = tables.Record("FuseObject from GT depth",
                                      {"world", "views x size", "person", "s", "points", "vertices",
                                       "chamfer mm", "fused->gt mm", "gt->fused mm"});
  bench::Table& poisson = tables.Record(
      "Poisson depth and threads",
      {"world", "views x size", "person", "depth", "threads", "s", "vertices", "chamfer mm"});
  bench::Table& tracked = tables.Record(
      "TrackVertices",
      {"world", "views x size", "person", "s per step", "vertices", "median drift mm per frame"});
  for (const std::string& world : bench::AvailableWorlds({"handshake", "realistic"})) {
    std::printf("== %s\n", world.c_str());
    for (const auto& [w, h, frames] : {std::tuple{480, 270, 11}, std::tuple{960, 540, 2}}) {
      synth::SynthOptions o = bench::World(world, 8, w, h, frames);
      o.write_meshes = true;
      if (world == "handshake") o.start_frame = 10;  // walking: centimetres of motion per frame
      const fs::path dir = synth::WriteCaptureToTempDir("fusion_bench", o);
      const Capture c = ReadCapture(dir);
      std::vector<Maps> maps;
      for (int f = 0; f < frames; ++f) maps.push_back(fusion_test::ReadGtFrame(c, f));
      for (int id = 1; id <= 2; ++id) {
        Timer t;
        const FusedMesh fm = FuseObject(maps[0].cameras, maps[0].depths, maps[0].ids,
                                        maps[0].images, id, FusionOptions{});
        const double fuse_s = t.Seconds();
        const auto gt = eval::ReadMesh(dir / layout::GtMesh(id, 0));
        const eval::ChamferResult r = eval::MeshChamfer(*fm.mesh, gt, {});
        std::printf(
            "8x%dx%d person %d: FuseObject %.2f s (%d points, %zu vertices), chamfer %.1f mm "
            "(fused->gt %.1f, gt->fused %.1f)\n",
            w, h, id, fuse_s, fm.num_points_used, fm.mesh->vertices_.size(), r.chamfer * 1e3,
            r.pred_to_gt * 1e3, r.gt_to_pred * 1e3);
        const std::string size = bench::Cell("8x%dx%d", w, h), person = std::to_string(id);
        fused.Row({world, size, person, bench::Cell("%.2f", fuse_s),
                   std::to_string(fm.num_points_used), std::to_string(fm.mesh->vertices_.size()),
                   bench::Cell("%.1f", r.chamfer * 1e3), bench::Cell("%.1f", r.pred_to_gt * 1e3),
                   bench::Cell("%.1f", r.gt_to_pred * 1e3)});
        if (frames < 3) continue;  // tracking only on the 10-frame segment
        for (const auto& [depth, threads] : {std::pair{8, 1}, std::pair{8, 2}, std::pair{7, 1},
                                             std::pair{7, 2}, std::pair{9, 1}}) {
          FusionOptions fo;
          fo.poisson_depth = depth;
          fo.poisson_threads = threads;
          Timer tp;
          const FusedMesh pm =
              FuseObject(maps[0].cameras, maps[0].depths, maps[0].ids, maps[0].images, id, fo);
          const double pm_s = tp.Seconds();
          const eval::ChamferResult pr = eval::MeshChamfer(*pm.mesh, gt, {});
          std::printf(
              "  poisson depth %d, %d thread(s): FuseObject %.2f s, %zu vertices, chamfer "
              "%.2f mm\n",
              depth, threads, pm_s, pm.mesh->vertices_.size(), pr.chamfer * 1e3);
          poisson.Row({world, size, person, std::to_string(depth), std::to_string(threads),
                       bench::Cell("%.2f", pm_s), std::to_string(pm.mesh->vertices_.size()),
                       bench::Cell("%.2f", pr.chamfer * 1e3)});
        }
        // Track over the segment; drift against the matched GT vertices.
        open3d::geometry::PointCloud gt0;
        gt0.points_ = gt.vertices_;
        open3d::geometry::KDTreeFlann tree(gt0);
        const auto& verts = fm.mesh->vertices_;
        std::vector<int> match(verts.size()), idx(1);
        std::vector<double> d2(1);
        for (size_t i = 0; i < verts.size(); ++i) {
          tree.SearchKNN(verts[i], 1, idx, d2);
          match[i] = idx[0];
        }
        Timer tt;
        const AnimatedMesh seg = TrackSegment(
            *fm.mesh, id, 0, frames - 1, [&](int k) { return Step(maps[k], maps[k + 1]); },
            TrackOptions{});
        const double track_s = tt.Seconds() / (frames - 1);
        std::printf("  TrackVertices %.3f s per step (%d vertices, 8 views); median drift (mm):",
                    track_s, seg.NumVertices());
        std::string drifts;
        for (int k = 1; k < frames; ++k) {
          const auto gk = eval::ReadMesh(dir / layout::GtMesh(id, k));
          std::vector<double> drift;
          for (size_t i = 0; i < verts.size(); ++i)
            drift.push_back(
                (seg.positions[k][i] - (gk.vertices_[match[i]] + verts[i] - gt.vertices_[match[i]]))
                    .norm());
          std::printf(" %.1f", Median(drift) * 1e3);
          drifts += bench::Cell(" %.1f", Median(drift) * 1e3);
        }
        std::printf("\n");
        tracked.Row({world, size, person, bench::Cell("%.3f", track_s),
                     std::to_string(seg.NumVertices()), drifts.substr(1)});
      }
      fs::remove_all(dir);
    }
  }
  tables.Write();
  return 0;
}
