// Relative paths of everything in a capture and in a 4D scene, in one place.
// docs/formats.md documents the same layout for people; keep them in step.
// Frames are numbered from 0 and written with six digits.
#pragma once

#include <string>

#include "u4d/util/file.h"

namespace u4d::layout {

std::string FrameName(int frame);  // "000042"

// Capture inputs (relative to the capture root).
fs::path Image(const std::string& view, int frame);     // images/<view>/<frame>.png
fs::path Mask(const std::string& view, int frame);      // masks/<view>/<frame>.png
fs::path MaskInfo(const std::string& view, int frame);  // masks/<view>/<frame>.json
fs::path Poses2d(const std::string& view, int frame);   // poses2d/<view>/<frame>.json
fs::path Poses3d(int frame);                            // poses3d/<frame>.json
fs::path CleanPlateDir();  // background/ (io/clean_plate.h: <view>.png|jpg or <view>/ frames)

// Ground truth (relative to the capture root).
fs::path GtInstances(const std::string& view, int frame);      // gt/instances/<view>/<frame>.png
fs::path GtInstancesInfo(const std::string& view, int frame);  // gt/instances/<view>/<frame>.json
fs::path GtDepth(const std::string& view, int frame);          // gt/depth/<view>/<frame>.pfm
fs::path GtFlow(const std::string& view, int frame);           // gt/flow/<view>/<frame>.flo
fs::path GtFlowValid(const std::string& view, int frame);      // gt/flow_valid/<view>/<frame>.png
fs::path GtVisibility(const std::string& view, int frame);     // gt/visibility/<view>/<frame>.json
fs::path GtJoints3d(int frame);                                // gt/joints3d/<frame>.json
fs::path GtMesh(int object_id, int frame);                     // gt/meshes/<id>/<frame>.ply
fs::path GtContacts();                                         // gt/contacts.json

// The 4D scene written by `u4d run` (relative to its output root). Per-view
// maps have the camera's size. Object ids are the instance ids of the
// refined masks (>= 1, the same in every view and frame).
fs::path SceneIndex();        // scene.json: frames, views, objects, files, stages done
fs::path SceneCalibration();  // calibration.json (as in a capture)
fs::path SceneParams();       // params.json: every option used
fs::path SceneInputs();       // inputs.json: the capture's fingerprint (io/input_fingerprint.h)
fs::path SceneKeyframes();    // keyframes.json
fs::path SceneEval();         // eval.json (only with ground truth)
fs::path SceneConsistency();  // consistency.json (figures that need no ground truth)
fs::path SceneInstances(const std::string& view, int frame);      // instances/<view>/<frame>.png
fs::path SceneInstancesInfo(const std::string& view, int frame);  // instances/<view>/<frame>.json
fs::path SceneDepth(const std::string& view,
                    int frame);                          // depth/<view>/<frame>.pfm (z m, 0 = none)
fs::path SceneFlow(const std::string& view, int frame);  // flow/<view>/<frame>.flo (t -> t+1)
// PNG pictures for people (io/visualize.h), read by the web viewer: kind is
// "image" (a copy of the input frame, downscaled for the viewer), "instances",
// "depth" or "flow"; pictures may be smaller than the camera.
fs::path ScenePicture(const std::string& kind, const std::string& view, int frame);
fs::path ScenePoses3d(int frame);               // poses3d/<frame>.json
fs::path SceneTracks(const std::string& view);  // tracks/<view>.json
fs::path SceneMesh(int object_id, int frame);   // meshes/<id>/<frame>.ply (colour, label)
fs::path SceneSegmentDir(int segment);          // segments/<kk>/ (segment.json, <id>.glb)
// What the run started from (kept so that a resumed run starts from the same):
// the initial masks with object ids, and per frame the objects' depth ranges.
fs::path SceneInitialMask(const std::string& view, int frame);  // initial/masks/<view>/<frame>.png
fs::path SceneInitialObjects(int frame);                        // initial/objects/<frame>.json
fs::path SceneRunLog();  // run.json: stages and segments done, time and memory per stage

}  // namespace u4d::layout
