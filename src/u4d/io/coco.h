// COCO instance annotations (https://cocodataset.org/#format-data): reading a
// dataset file or a detector results file, turning the annotations of one
// image into a u4d::InstanceMask, and run-length encoding masks so U4D can
// write COCO results. docs/annotations.md has the conventions in prose.
//
// Files:
//  - a dataset file: {"images": [{"id", "file_name", "width", "height"}],
//    "categories": [{"id", "name"}], "annotations": [...]};
//  - a results file: a JSON array of annotations (no images or categories;
//    ReadCocoResults borrows them from the dataset the results refer to).
// An annotation's "segmentation" is one of
//  - polygons: [[x1, y1, x2, y2, ...], ...] (each >= 3 vertices; the parts of
//    one object, united);
//  - uncompressed RLE: {"size": [h, w], "counts": [n0, n1, ...]};
//  - compressed RLE: {"size": [h, w], "counts": "<string>"}.
// RLE runs scan the image column by column (column-major, "Fortran" order),
// alternate background / foreground and start with background (a mask whose
// first pixel is foreground starts with a run of 0); they sum to h * w.
// The compressed string stores each run (from the fourth, index 3, on as the
// difference to the run two before) in 5-bit groups, least significant first, each group
// plus a continuation bit (0x20) offset by 48 into printable ASCII; the last
// group's bit 0x10 is the sign.
//
// Pixel convention: COCO polygon vertices are continuous coordinates with the
// image's top-left CORNER at (0, 0) (pixel (c, r) covers [c, c+1] x [r, r+1],
// its centre is (c + 0.5, r + 0.5)); U4D's pixel-centre origin
// (docs/conventions.md) is COCO's (0.5, 0.5). A pixel belongs to a polygon
// when its centre lies inside (even-odd rule within one part; a centre exactly
// on a left / top edge is inside, on a right / bottom edge outside), so a
// w x h axis-aligned box covers exactly w * h pixels. cv::fillPoly is not
// used: it fills the boundary pixels at both ends of every span, which makes
// a w x h box (w + 1) x (h + 1) and every mask larger by about half a pixel
// per unit of perimeter, more than COCO's own "area" field allows.
//
// Every reader throws u4d::Error naming the file (or the `context` string) on
// a missing file, malformed JSON, missing or mistyped fields, an image that is
// not in the file, odd polygon lengths, non-finite numbers, RLE runs that do
// not sum to h * w, or an RLE size that differs from the image's size.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "u4d/io/instance_mask.h"
#include "u4d/util/file.h"

namespace u4d {

struct CocoImage {
  int64_t id = 0;
  std::string file_name;
  int width = 0;
  int height = 0;
};

struct CocoCategory {
  int64_t id = 0;
  std::string name;
};

// A run-length encoded binary mask (see the header comment for the layout).
struct CocoRle {
  int height = 0;
  int width = 0;
  std::vector<uint32_t> counts;  // column-major runs, background first
};

struct CocoAnnotation {
  int64_t id = 0;  // 0 when the file has none (results files)
  int64_t image_id = 0;
  int64_t category_id = 0;
  bool iscrowd = false;
  std::optional<double> score;  // results files only
  double area = 0;              // the file's "area" (0 if absent)
  // Exactly one of the two holds the segmentation; both are empty for an
  // annotation without one (e.g. keypoints-only results).
  std::vector<std::vector<double>> polygons;  // COCO coordinates (corner origin)
  std::optional<CocoRle> rle;
  // "keypoints": 3 * K numbers (x, y, v), empty if absent.
  std::vector<double> keypoints;
};

struct CocoFile {
  std::string context;  // the file name, for error messages
  std::vector<CocoImage> images;
  std::vector<CocoCategory> categories;
  std::vector<CocoAnnotation> annotations;  // in file order
};

// Parses a dataset file (object) or a results file (array; no images or
// categories). Throws naming the file on any malformed entry.
CocoFile ReadCocoFile(const fs::path& path);
CocoFile ParseCoco(const nlohmann::json& json, const std::string& context);

// Reads a results file and takes images and categories from `dataset`; every
// result must refer to an image and a category of the dataset.
CocoFile ReadCocoResults(const fs::path& path, const CocoFile& dataset);

// The image with this file name (compared with the whole "file_name" and,
// failing that, with its last path component) or id. Throws naming the file.
const CocoImage& FindCocoImage(const CocoFile& coco, const std::string& file_name);
const CocoImage& FindCocoImage(const CocoFile& coco, int64_t image_id);
// The category's name; throws naming the file if the id is unknown.
const std::string& CocoCategoryName(const CocoFile& coco, int64_t category_id);

// Polygons in COCO coordinates -> CV_8UC1 mask (1 inside, 0 outside), the
// union of the parts, by the pixel-centre rule above. Throws naming `context` on an odd length,
// fewer than 3 vertices, or a non-finite coordinate.
cv::Mat RasterizeCocoPolygons(const std::vector<std::vector<double>>& polygons, int height,
                              int width, const std::string& context);

// RLE <-> CV_8UC1 mask (1 = foreground). EncodeRle treats every non-zero
// pixel of a CV_8UC1 mask as foreground. DecodeRle throws naming `context` if
// the runs do not sum to height * width or the size is not positive.
CocoRle EncodeRle(const cv::Mat& mask);
cv::Mat DecodeRle(const CocoRle& rle, const std::string& context);

// The compressed string form of RLE counts, and back. DecompressRleCounts
// throws naming `context` on characters outside the alphabet, a truncated
// last run, or negative runs.
std::string CompressRleCounts(const std::vector<uint32_t>& counts);
std::vector<uint32_t> DecompressRleCounts(const std::string& text, const std::string& context);

// One annotation's mask at the image size (polygons rasterised, RLE decoded).
// Throws naming the file when an RLE's size differs from (height, width) or
// the annotation has no segmentation.
cv::Mat CocoAnnotationMask(const CocoFile& coco, const CocoAnnotation& annotation, int height,
                           int width);

struct CocoMaskOptions {
  // Crowd regions (iscrowd = 1) are groups of people, not instances; skipped
  // unless set.
  bool include_crowd = false;
  // Only annotations of this category name; empty = every category.
  std::string category;
  // Annotations with a score below this are skipped (annotations without a
  // score count as 1).
  double min_score = 0.0;

  void Check() const;  // min_score in [0, 1]
};

// The annotations of `image` that pass `options`, in file order. Instance id
// k (1-based) of CocoInstanceMask is the k-th of these; the pose readers in
// poses.h use the same numbering for person_id.
std::vector<const CocoAnnotation*> SelectCocoAnnotations(const CocoFile& coco,
                                                         const CocoImage& image,
                                                         const CocoMaskOptions& options = {});

// The instance mask of one image: ids 1..N in annotation order (of the
// selected annotations), label = category name, score = the annotation's
// "score" or 1. Overlaps: a pixel claimed by several annotations goes to the
// one with the higher score; on equal scores to the one with the smaller mask
// area (a small region inside a large one is the object in front, or it would
// vanish entirely); on equal area to the earlier annotation. Instances may end
// up with fewer pixels than their own masks, or none; they stay listed.
InstanceMask CocoInstanceMask(const CocoFile& coco, const CocoImage& image,
                              const CocoMaskOptions& options = {});

// COCO results (one annotation per instance present in the mask, compressed
// RLE segmentation, "score" and "area") for `image_id`; category ids come from
// `coco.categories` by the instance's label (throws if a label is unknown).
nlohmann::json CocoResultsFromInstanceMask(const InstanceMask& mask, int64_t image_id,
                                           const CocoFile& coco);

}  // namespace u4d
