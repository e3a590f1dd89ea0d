// The class of every object of a run (docs/formats.md "Classes"): the
// initial masks' classes (masks/<view>/<frame>.json "class", or a COCO
// category name, io/instance_mask.h) carried to the objects that the initial
// stage forms from them (initial_objects.h).
//
// An object's pixels in a view may come from several detector instances (a
// fragment joined to it, a merged instance split between people). Per view
// and frame the object votes once, for the class of the detector instances
// under most of its pixels; over the run the object's class is the class with
// the most votes (views and frames alike), so that one view's mistake does
// not relabel an object. A tie goes to "person" when it is among the tied,
// else to the alphabetically first. An object without a vote (found without
// masks, e.g. init/init.h's unsupervised masks, or by the poses alone) is a
// "person" (kDefaultClass).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "u4d/features/sparse_points.h"
#include "u4d/io/instance_mask.h"
#include "u4d/util/file.h"

namespace u4d {

inline constexpr const char* kDefaultClass = "person";

// object id -> class name -> number of view-frames voting for it.
using ClassVotes = std::map<int, std::map<std::string, int>>;

// The votes of one frame: `objects[v]` (CV_16U object ids; empty = no mask)
// against `detections[v]` (the detector's instances of the same view and
// size; empty ids = none). Detector pixels that are background or whose id
// has no entry do not vote. Throws u4d::Error when the vectors' lengths or a
// view's image sizes differ.
ClassVotes VoteObjectClasses(const std::vector<cv::Mat>& objects,
                             const std::vector<InstanceMask>& detections);

// The id images of `masks` (an empty Mat where a view has none).
std::vector<cv::Mat> IdImages(const std::vector<InstanceMask>& masks);

// The class of every instance of `masks`, per view (features/sparse_points.h).
InstanceClasses InstanceClassesOf(const std::vector<InstanceMask>& masks);

// `masks` with only the instances that are people (`people`) or only those
// that are not: the others' pixels become background and leave the list. A
// view without a mask (empty ids) stays without.
std::vector<InstanceMask> KeepInstances(const std::vector<InstanceMask>& masks, bool people);

// Adds `votes` to `total`.
void AddClassVotes(const ClassVotes& votes, ClassVotes* total);

// Each voted object's majority class (ties as above).
std::map<int, std::string> MajorityClasses(const ClassVotes& votes);

// The class of object `id`: its entry, else kDefaultClass.
std::string ObjectClass(const std::map<int, std::string>& classes, int id);

// Whether objects of `class_name` are people (the pose prior acts on them).
bool IsPersonClass(const std::string& class_name);

// The votes as stored in initial/objects/<frame>.json: {"<id>": {"<class>":
// votes}}. Reading throws u4d::Error naming `context` on another shape, an id
// < 1 or a vote count < 1.
nlohmann::json ClassVotesToJson(const ClassVotes& votes);
ClassVotes ClassVotesFromJson(const nlohmann::json& j, const std::string& context);

// The votes stored in initial/objects/<frame>.json ("classes") of frames
// [first, last), summed, and their majority classes. A frame file without
// "classes" (written before classes were carried) adds nothing. Throws
// u4d::Error naming the file when one is missing or "classes" is malformed.
std::map<int, std::string> ReadRunObjectClasses(const fs::path& scene, int first, int last);

}  // namespace u4d
