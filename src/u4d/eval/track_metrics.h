// Sparse temporal tracks (features/temporal_tracks.h) against a synthetic
// capture's ground-truth flow. Used by features_temporal_tracks_test and
// bench/tracks_bench.cc; not part of the pipeline.
#pragma once

#include <vector>

#include "u4d/features/temporal_tracks.h"
#include "u4d/io/capture.h"

namespace u4d {

// Precision of feature tracks against the capture's GT forward flow
// (gt/flow/<view>/<t>.flo, gt/flow_valid). For each pair of consecutive
// points (t1, p1), (t2, p2) of a feature track (joint tracks are skipped),
// p1 is carried from t1 to t2 by composing the GT flow (bilinear flow, each
// step needing a valid flow at the nearest pixel); the pair is evaluated
// only when every step is valid and stays inside the image. It is correct
// when |p2 - carried| <= max_error_px.
struct TrackPrecision {
  long evaluated = 0;              // point pairs with valid GT
  long correct = 0;                // of those within max_error_px
  long consecutive_evaluated = 0;  // the pairs with t2 = t1 + 1
  long consecutive_correct = 0;
  double Precision() const { return evaluated ? static_cast<double>(correct) / evaluated : 0; }
};
TrackPrecision EvaluateTracksWithGtFlow(const Capture& capture,
                                        const std::vector<TemporalTrack>& tracks,
                                        double max_error_px = 2.0);

}  // namespace u4d
