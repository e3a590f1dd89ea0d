// `u4d run <capture> -o <scene>`: the whole method on a capture, writing the
// 4D scene (io/layout.h, docs/formats.md "The 4D scene", docs/pipeline.md).
//
// Stages, in the order of the data flow (paper Sec. 2-4):
//   poses      3D poses: given (poses3d/), or triangulated from the 2D
//              keypoints (poses2d/) and tracked (pose/), or none
//   initial    per frame: the initial masks (given masks/, or unsupervised,
//              init/init.h) turned into object ids (initial_objects.h)
//   tracks     sparse temporal correspondences per view (features/temporal_tracks.h),
//              linked within chunks of RunOptions::track_chunk_frames frames
//   keyframes  KS_ij and the key-frames (keyframes/keyframe_similarity.h);
//              the temporal segments K_s <= t < K_{s+1}
//   segments   per segment, frame by frame: the joint optimisation of every
//              view (in parallel), the per-object fusion into meshes, and the
//              key-frame meshes moved through the segment by the scene flow
//              (one topology per object per segment, segments/<kk>/<id>.glb)
//   eval       eval.json against gt/ when the capture has ground truth and the
//              whole capture was run
// Memory: only the frames t-1..t+1 of the segment being solved and the
// meshes being tracked are held, so it stays flat with the capture's length.
//
// Resume: run.json (run_log.h) records the stages and segments finished; a
// run into a scene directory written from the same options (params.json) and
// the same inputs (inputs.json, the capture's fingerprint) skips them. A
// scene written with other options, or from the same capture whose
// calibration, masks, poses or frames changed since, is recomputed: the run
// prints what changed (the option or the files, scene_resume.h), removes the
// earlier run's outputs and computes everything, as it does when
// RunOptions::resume is false. A scene of another capture (another path) is
// refused with u4d::Error unless RunOptions::resume is false.
// A resumed run first removes the temporary files of the writes a killed run
// left (each file is written to a temporary name and renamed into place).
//
// Nothing found: when the initial stage finds no object in any view of any
// frame, the run throws u4d::Error saying what would help (masks, poses),
// after recording that stage, unless RunOptions::allow_empty. Frames left
// empty in a run that found objects elsewhere are listed in run.json
// ("empty_frames") and RunResult.
//
// Bad input: a missing or corrupt frame, mask or pose file throws u4d::Error
// naming it; the segment being solved is then not recorded as done, and what
// was finished before stays valid (run again to resume).
#pragma once

#include <string>
#include <vector>

#include "u4d/pipeline/run_log.h"
#include "u4d/pipeline/run_options.h"
#include "u4d/util/file.h"

namespace u4d {

struct RunResult {
  RunLog log;      // sources, stages done, time and memory per stage
  int frames = 0;  // frames run
  int views = 0;
  int objects = 0;  // object ids seen
  int keyframes = 0;
  int segments = 0;               // temporal segments
  int segments_skipped = 0;       // already done by an earlier run
  bool evaluated = false;         // eval.json written
  std::vector<int> empty_frames;  // frames with no object in any view (they stay empty)
};

RunResult RunPipeline(const fs::path& capture_dir, const fs::path& scene_dir,
                      const RunOptions& options);

}  // namespace u4d
