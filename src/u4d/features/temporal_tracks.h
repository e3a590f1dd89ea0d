// Sparse temporal correspondence tracks per view (paper Sec. 2.1.3, "Sparse
// temporal correspondences").
//
// Per view c and frame t: SIFT features F^c_t (cv::SIFT), optionally only
// inside the dilated initial instance masks. Features of frame i are matched
// to every frame j in (i, i + window] of the same view by nearest-neighbour
// matching with Lowe's ratio test, followed by the paper's symmetry test: a
// match a -> b is kept only when the backward matching of frame j to frame i
// maps b back to a (two-way consistency). Matches are linked into tracks
// with union-find over the (frame, keypoint) nodes; a component that holds
// two different keypoints of the same frame is inconsistent and dropped.
// Components with at least two frames are the feature tracks. The 3D joints
// of each frame (Pose3d, H36M-17) are projected into the view and added as
// joint tracks (one per person and joint), as in the paper.
//
// A track's instance is the majority instance id (of the masks used for the
// features) under its points; 0 when it falls on the background or when no
// masks were given.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/io/capture.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/poses.h"

namespace u4d {

struct TemporalTrack {
  int view = -1;     // index into Capture::views
  int instance = 0;  // majority mask instance id under the points; 0 = none
  // (frame, pixel) in increasing frame order, at most one point per frame.
  std::vector<std::pair<int, Eigen::Vector2d>> points;
  bool from_joint = false;  // a projected 3D joint rather than a SIFT track
  int joint = -1;           // H36M-17 joint index for joint tracks, else -1
  int person_id = -1;       // Pose3d::person_id for joint tracks, else -1

  // The pixel at `frame`, or nullptr when the track has no point there.
  const Eigen::Vector2d* At(int frame) const;
};

struct TemporalTrackOptions {
  int window = 10;                    // frames i is matched to: j in (i, i + window]
  double ratio = 0.8;                 // Lowe's ratio: best < ratio * second best distance
  bool symmetry_test = true;          // keep only matches found both forwards and backwards
  int max_features = 1500;            // SIFT features per frame (strongest kept); 0 = all
  double contrast_threshold = 0.03;   // cv::SIFT contrastThreshold (lower: more features)
  bool restrict_to_masks = true;      // detect only inside the dilated instance masks
  int mask_dilation_px = 4;           // dilation of the masks (pixels) before restricting
  bool add_joint_tracks = true;       // add projected 3D joints as tracks
  double min_joint_confidence = 0.1;  // joints below this confidence are skipped

  void Check() const;  // throws u4d::Error on a non-positive window, ratio outside (0, 1], ...
};

// Features of one frame of one view.
struct FrameFeatures {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;        // CV_32F, one row per keypoint
  std::vector<int> instance;  // mask instance id at each keypoint (0 = none)
};

// SIFT on `image` (BGR or grey). With a non-empty `mask` (CV_16UC1 ids) and
// options.restrict_to_masks, only inside the dilated foreground. Throws when
// the mask size differs from the image's.
FrameFeatures DetectFrameFeatures(const cv::Mat& image, const cv::Mat& mask_ids,
                                  const TemporalTrackOptions& options);

// Counts from one matching of two frames.
struct MatchCounts {
  int one_way = 0;    // forward matches passing the ratio test
  int symmetric = 0;  // of those, also found backwards (the symmetry test)
};

// Nearest-neighbour matching a -> b with the ratio test; with
// options.symmetry_test also b -> a, keeping only mutual matches. DMatch has
// queryIdx in a and trainIdx in b. `counts` (optional) receives both counts.
std::vector<cv::DMatch> MatchFrameFeatures(const FrameFeatures& a, const FrameFeatures& b,
                                           const TemporalTrackOptions& options,
                                           MatchCounts* counts = nullptr);

struct TrackStats {
  int frame_pairs = 0;         // frame pairs matched
  long one_way_matches = 0;    // summed over the pairs
  long symmetric_matches = 0;  // summed over the pairs
  int dropped_components = 0;  // linked components with two keypoints in one frame
  double seconds_detect = 0;   // wall time in feature detection
  double seconds_match = 0;    // wall time in matching
};

// Feature tracks of one view from the features of consecutive frames
// frames[0..n-1] = capture frames first_frame..first_frame+n-1.
std::vector<TemporalTrack> LinkFeatureTracks(int view, int first_frame,
                                             const std::vector<FrameFeatures>& frames,
                                             const TemporalTrackOptions& options,
                                             TrackStats* stats = nullptr);

// One track per (person, joint): the joints of poses[k] (frame first_frame+k)
// projected with the view's camera at that frame; points outside the image,
// behind the camera or below min_joint_confidence are skipped. `mask_ids`
// (optional, per frame, may be empty) gives the instance.
std::vector<TemporalTrack> JointTracks(const Capture& capture, int view, int first_frame,
                                       const std::vector<std::vector<Pose3d>>& poses,
                                       const std::vector<cv::Mat>& mask_ids,
                                       const TemporalTrackOptions& options);

// tracks/<view>.json of a 4D scene (io/layout.h SceneTracks):
//   {"format": "u4d-tracks", "view": "cam00",
//    "tracks": [{"id": 0, "instance": 1, "from_joint": false, "joint": -1, "person_id": -1,
//                "points": [[frame, x, y], ...]}]}
// Written atomically with the tracks of `view` only, numbered from 0 (pixels
// of the camera, as the viewer draws them). Reading throws
// u4d::Error naming the file on a wrong format, a missing field, frames not
// strictly increasing or a non-finite pixel.
void WriteTemporalTracks(const fs::path& path, const std::string& view_name, int view,
                         const std::vector<TemporalTrack>& tracks);
std::vector<TemporalTrack> ReadTemporalTracks(const fs::path& path, int view);

}  // namespace u4d
