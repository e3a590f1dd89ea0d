#include "u4d/io/coco.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <opencv2/imgproc.hpp>  // boundingRect

#include "u4d/util/check.h"

namespace u4d {
namespace {

using nlohmann::json;

double Number(const json& v, const std::string& ctx, const std::string& what) {
  return JsonNumber(v, ctx, what);
}

int64_t Integer(const json& v, const std::string& ctx, const std::string& what) {
  return JsonInteger(v, ctx, what);
}

CocoRle ParseRle(const json& seg, const std::string& ctx) {
  U4D_CHECK(seg.contains("size") && seg["size"].is_array() && seg["size"].size() == 2,
            "{}: RLE 'size' must be [height, width]", ctx);
  CocoRle rle;
  const int64_t h = Integer(seg["size"][0], ctx, "RLE height");
  const int64_t w = Integer(seg["size"][1], ctx, "RLE width");
  U4D_CHECK(h > 0 && w > 0 && h < 100000 && w < 100000,
            "{}: bad RLE size [{}, {}] (expected positive height and width)", ctx, h, w);
  rle.height = static_cast<int>(h);
  rle.width = static_cast<int>(w);
  U4D_CHECK(seg.contains("counts"), "{}: RLE without 'counts'", ctx);
  const json& counts = seg["counts"];
  if (counts.is_string()) {
    rle.counts = DecompressRleCounts(counts.get<std::string>(), ctx);
  } else {
    U4D_CHECK(counts.is_array(), "{}: RLE 'counts' must be a string or an array", ctx);
    for (const json& c : counts) {
      const int64_t n = Integer(c, ctx, "RLE count");
      U4D_CHECK(n >= 0 && n <= std::numeric_limits<uint32_t>::max(),
                "{}: RLE count {} out of range", ctx, n);
      rle.counts.push_back(static_cast<uint32_t>(n));
    }
  }
  uint64_t sum = 0;
  for (uint32_t c : rle.counts) sum += c;
  U4D_CHECK(sum == static_cast<uint64_t>(h) * static_cast<uint64_t>(w),
            "{}: RLE counts sum to {}, expected height * width = {} * {} = {}", ctx, sum, h, w,
            h * w);
  return rle;
}

CocoAnnotation ParseAnnotation(const json& a, const std::string& ctx) {
  U4D_CHECK(a.is_object(), "{}: expected an object", ctx);
  CocoAnnotation ann;
  if (a.contains("id")) ann.id = Integer(a["id"], ctx, "'id'");
  U4D_CHECK(a.contains("image_id"), "{}: missing field 'image_id'", ctx);
  ann.image_id = Integer(a["image_id"], ctx, "'image_id'");
  U4D_CHECK(a.contains("category_id"), "{}: missing field 'category_id'", ctx);
  ann.category_id = Integer(a["category_id"], ctx, "'category_id'");
  if (a.contains("iscrowd")) ann.iscrowd = Integer(a["iscrowd"], ctx, "'iscrowd'") != 0;
  if (a.contains("score")) {
    ann.score = Number(a["score"], ctx, "'score'");
    U4D_CHECK(*ann.score >= 0 && *ann.score <= 1, "{}: score {} outside [0, 1]", ctx, *ann.score);
  }
  if (a.contains("area")) ann.area = Number(a["area"], ctx, "'area'");
  if (a.contains("segmentation")) {
    const json& seg = a["segmentation"];
    if (seg.is_array()) {
      for (const json& poly : seg) {
        U4D_CHECK(poly.is_array(), "{}: a polygon must be an array of numbers", ctx);
        std::vector<double> xy;
        for (const json& v : poly) xy.push_back(Number(v, ctx, "polygon coordinate"));
        U4D_CHECK(xy.size() % 2 == 0 && xy.size() >= 6,
                  "{}: polygon with {} numbers (expected an even count >= 6)", ctx, xy.size());
        ann.polygons.push_back(std::move(xy));
      }
    } else {
      U4D_CHECK(seg.is_object(), "{}: 'segmentation' must be polygons or RLE", ctx);
      ann.rle = ParseRle(seg, ctx);
    }
  }
  if (a.contains("keypoints")) {
    U4D_CHECK(a["keypoints"].is_array(), "{}: 'keypoints' must be an array", ctx);
    for (const json& v : a["keypoints"]) ann.keypoints.push_back(Number(v, ctx, "keypoint value"));
    U4D_CHECK(ann.keypoints.size() % 3 == 0, "{}: {} keypoint values (not a multiple of 3)", ctx,
              ann.keypoints.size());
  }
  return ann;
}

std::vector<CocoAnnotation> ParseAnnotations(const json& arr, const std::string& ctx) {
  U4D_CHECK(arr.is_array(), "{}: 'annotations' must be an array", ctx);
  std::vector<CocoAnnotation> out;
  out.reserve(arr.size());
  for (size_t i = 0; i < arr.size(); ++i)
    out.push_back(ParseAnnotation(arr[i], fmt::format("{}: annotation {}", ctx, i)));
  return out;
}

}  // namespace

CocoFile ParseCoco(const json& j, const std::string& context) {
  CocoFile coco;
  coco.context = context;
  if (j.is_array()) {
    coco.annotations = ParseAnnotations(j, context);
    return coco;
  }
  U4D_CHECK(j.is_object(), "{}: expected a COCO object or a results array", context);
  U4D_CHECK(j.contains("images"), "{}: missing field 'images'", context);
  U4D_CHECK(j.contains("annotations"), "{}: missing field 'annotations'", context);
  U4D_CHECK(j["images"].is_array(), "{}: 'images' must be an array", context);
  for (size_t i = 0; i < j["images"].size(); ++i) {
    const json& im = j["images"][i];
    const std::string ctx = fmt::format("{}: image {}", context, i);
    CocoImage image;
    image.id = JsonGet<int64_t>(im, "id", ctx);
    image.file_name = JsonGet<std::string>(im, "file_name", ctx);
    image.width = JsonGet<int>(im, "width", ctx);
    image.height = JsonGet<int>(im, "height", ctx);
    U4D_CHECK(image.width > 0 && image.height > 0 && image.width < 100000 && image.height < 100000,
              "{}: bad size {}x{} (expected 1-99999 each)", ctx, image.width, image.height);
    coco.images.push_back(image);
  }
  if (j.contains("categories")) {
    U4D_CHECK(j["categories"].is_array(), "{}: 'categories' must be an array", context);
    for (size_t i = 0; i < j["categories"].size(); ++i) {
      const std::string ctx = fmt::format("{}: category {}", context, i);
      CocoCategory cat;
      cat.id = JsonGet<int64_t>(j["categories"][i], "id", ctx);
      cat.name = JsonGet<std::string>(j["categories"][i], "name", ctx);
      coco.categories.push_back(cat);
    }
  }
  coco.annotations = ParseAnnotations(j["annotations"], context);
  return coco;
}

CocoFile ReadCocoFile(const fs::path& path) { return ParseCoco(ReadJsonFile(path), path.string()); }

CocoFile ReadCocoResults(const fs::path& path, const CocoFile& dataset) {
  const json j = ReadJsonFile(path);
  U4D_CHECK(j.is_array(), "{}: a results file must be a JSON array of annotations", path.string());
  CocoFile coco = ParseCoco(j, path.string());
  coco.images = dataset.images;
  coco.categories = dataset.categories;
  for (size_t i = 0; i < coco.annotations.size(); ++i) {
    const CocoAnnotation& a = coco.annotations[i];
    const bool has_image = std::any_of(coco.images.begin(), coco.images.end(),
                                       [&](const CocoImage& im) { return im.id == a.image_id; });
    U4D_CHECK(has_image, "{}: result {} refers to image {}, which is not in {}", path.string(), i,
              a.image_id, dataset.context);
    CocoCategoryName(coco, a.category_id);
  }
  return coco;
}

const CocoImage& FindCocoImage(const CocoFile& coco, const std::string& file_name) {
  for (const CocoImage& im : coco.images)
    if (im.file_name == file_name) return im;
  for (const CocoImage& im : coco.images)
    if (fs::path(im.file_name).filename() == fs::path(file_name).filename()) return im;
  ThrowError(fmt::format("{}: no image with file name '{}' ({} images)", coco.context, file_name,
                         coco.images.size()));
}

const CocoImage& FindCocoImage(const CocoFile& coco, int64_t image_id) {
  for (const CocoImage& im : coco.images)
    if (im.id == image_id) return im;
  ThrowError(fmt::format("{}: no image with id {} ({} images)", coco.context, image_id,
                         coco.images.size()));
}

const std::string& CocoCategoryName(const CocoFile& coco, int64_t category_id) {
  for (const CocoCategory& c : coco.categories)
    if (c.id == category_id) return c.name;
  ThrowError(fmt::format("{}: unknown category id {}", coco.context, category_id));
}

cv::Mat RasterizeCocoPolygons(const std::vector<std::vector<double>>& polygons, int height,
                              int width, const std::string& context) {
  U4D_CHECK(height > 0 && width > 0, "{}: bad mask size {}x{}", context, width, height);
  cv::Mat mask = cv::Mat::zeros(height, width, CV_8UC1);
  std::vector<double> xs;
  for (const std::vector<double>& xy : polygons) {
    U4D_CHECK(xy.size() % 2 == 0 && xy.size() >= 6,
              "{}: polygon with {} numbers (expected an even count >= 6)", context, xy.size());
    const size_t n = xy.size() / 2;
    double ymin = std::numeric_limits<double>::infinity(), ymax = -ymin;
    for (size_t i = 0; i < n; ++i) {
      U4D_CHECK(std::isfinite(xy[2 * i]) && std::isfinite(xy[2 * i + 1]),
                "{}: polygon vertex {} is not finite", context, i);
      ymin = std::min(ymin, xy[2 * i + 1]);
      ymax = std::max(ymax, xy[2 * i + 1]);
    }
    // Rows whose centre (COCO y = r + 0.5) can be inside.
    const int r0 = std::max(0, static_cast<int>(std::floor(ymin - 0.5)));
    const int r1 = std::min(height - 1, static_cast<int>(std::ceil(ymax - 0.5)));
    for (int r = r0; r <= r1; ++r) {
      const double yc = r + 0.5;
      xs.clear();
      for (size_t i = 0; i < n; ++i) {
        const size_t j = (i + 1) % n;
        const double xi = xy[2 * i], yi = xy[2 * i + 1], xj = xy[2 * j], yj = xy[2 * j + 1];
        if ((yi <= yc) != (yj <= yc)) xs.push_back(xi + (yc - yi) * (xj - xi) / (yj - yi));
      }
      std::sort(xs.begin(), xs.end());
      uint8_t* row = mask.ptr<uint8_t>(r);
      for (size_t k = 0; k + 1 < xs.size(); k += 2) {
        // Pixels c with centre c + 0.5 in [xs[k], xs[k + 1]).
        const double a = std::max(xs[k] - 0.5, -1.0), b = std::min(xs[k + 1] - 0.5, width + 1.0);
        const int c0 = std::max(0, static_cast<int>(std::ceil(a)));
        const int c1 = std::min(width, static_cast<int>(std::ceil(b)));
        for (int c = c0; c < c1; ++c) row[c] = 1;
      }
    }
  }
  return mask;
}

CocoRle EncodeRle(const cv::Mat& mask) {
  U4D_CHECK(mask.type() == CV_8UC1 && !mask.empty(),
            "EncodeRle: expected a non-empty CV_8UC1 mask, got type {} size {}x{}", mask.type(),
            mask.cols, mask.rows);
  CocoRle rle;
  rle.height = mask.rows;
  rle.width = mask.cols;
  bool value = false;
  uint32_t run = 0;
  for (int c = 0; c < mask.cols; ++c) {
    for (int r = 0; r < mask.rows; ++r) {
      const bool p = mask.at<uint8_t>(r, c) != 0;
      if (p != value) {
        rle.counts.push_back(run);
        run = 0;
        value = p;
      }
      ++run;
    }
  }
  rle.counts.push_back(run);
  return rle;
}

cv::Mat DecodeRle(const CocoRle& rle, const std::string& context) {
  U4D_CHECK(rle.height > 0 && rle.width > 0, "{}: bad RLE size [{}, {}]", context, rle.height,
            rle.width);
  const uint64_t total = static_cast<uint64_t>(rle.height) * static_cast<uint64_t>(rle.width);
  const uint64_t sum = std::accumulate(rle.counts.begin(), rle.counts.end(), uint64_t{0});
  U4D_CHECK(sum == total, "{}: RLE counts sum to {}, expected height * width = {}", context, sum,
            total);
  cv::Mat mask = cv::Mat::zeros(rle.height, rle.width, CV_8UC1);
  uint64_t idx = 0;
  for (size_t i = 0; i < rle.counts.size(); ++i) {
    if (i % 2 == 1) {
      for (uint64_t k = idx; k < idx + rle.counts[i]; ++k)
        mask.at<uint8_t>(static_cast<int>(k % rle.height), static_cast<int>(k / rle.height)) = 1;
    }
    idx += rle.counts[i];
  }
  return mask;
}

std::string CompressRleCounts(const std::vector<uint32_t>& counts) {
  std::string out;
  for (size_t i = 0; i < counts.size(); ++i) {
    int64_t x = counts[i];
    if (i > 2) x -= static_cast<int64_t>(counts[i - 2]);
    bool more = true;
    while (more) {
      int64_t c = x & 0x1f;
      x >>= 5;  // arithmetic: keeps the sign
      more = (c & 0x10) ? x != -1 : x != 0;
      if (more) c |= 0x20;
      out.push_back(static_cast<char>(c + 48));
    }
  }
  return out;
}

std::vector<uint32_t> DecompressRleCounts(const std::string& text, const std::string& context) {
  std::vector<uint32_t> counts;
  size_t p = 0;
  while (p < text.size()) {
    int64_t x = 0;
    int k = 0;
    bool more = true;
    while (more) {
      U4D_CHECK(p < text.size(), "{}: compressed RLE string ends inside a run", context);
      const int c = static_cast<unsigned char>(text[p]) - 48;
      U4D_CHECK(c >= 0 && c < 64, "{}: character '{}' at {} is not in the compressed RLE alphabet",
                context, text[p], p);
      U4D_CHECK(k < 7, "{}: compressed RLE run at {} is too long", context, p);
      x |= static_cast<int64_t>(c & 0x1f) << (5 * k);
      more = (c & 0x20) != 0;
      ++p;
      ++k;
      if (!more && (c & 0x10)) x |= ~int64_t{0} << (5 * k);  // sign-extend
    }
    if (counts.size() > 2) x += counts[counts.size() - 2];
    U4D_CHECK(x >= 0 && x <= std::numeric_limits<uint32_t>::max(),
              "{}: compressed RLE decodes to run {} = {}", context, counts.size(), x);
    counts.push_back(static_cast<uint32_t>(x));
  }
  return counts;
}

cv::Mat CocoAnnotationMask(const CocoFile& coco, const CocoAnnotation& a, int height, int width) {
  const std::string ctx =
      fmt::format("{}: annotation {} (image {})", coco.context, a.id, a.image_id);
  if (!a.polygons.empty()) return RasterizeCocoPolygons(a.polygons, height, width, ctx);
  U4D_CHECK(a.rle.has_value(), "{}: no segmentation", ctx);
  U4D_CHECK(a.rle->height == height && a.rle->width == width,
            "{}: RLE size [{}, {}] differs from the image size [{}, {}]", ctx, a.rle->height,
            a.rle->width, height, width);
  return DecodeRle(*a.rle, ctx);
}

void CocoMaskOptions::Check() const {
  U4D_CHECK(std::isfinite(min_score) && min_score >= 0 && min_score <= 1,
            "CocoMaskOptions: min_score {} outside [0, 1]", min_score);
}

std::vector<const CocoAnnotation*> SelectCocoAnnotations(const CocoFile& coco,
                                                         const CocoImage& image,
                                                         const CocoMaskOptions& options) {
  options.Check();
  std::vector<const CocoAnnotation*> out;
  for (const CocoAnnotation& a : coco.annotations) {
    if (a.image_id != image.id) continue;
    if (a.iscrowd && !options.include_crowd) continue;
    if (a.score.value_or(1.0) < options.min_score) continue;
    if (!options.category.empty() && CocoCategoryName(coco, a.category_id) != options.category)
      continue;
    out.push_back(&a);
  }
  return out;
}

InstanceMask CocoInstanceMask(const CocoFile& coco, const CocoImage& image,
                              const CocoMaskOptions& options) {
  const std::vector<const CocoAnnotation*> anns = SelectCocoAnnotations(coco, image, options);
  U4D_CHECK(anns.size() < 65536, "{}: image {} has {} annotations; ids are 16-bit", coco.context,
            image.file_name, anns.size());
  InstanceMask out;
  out.ids = cv::Mat::zeros(image.height, image.width, CV_16UC1);
  std::vector<cv::Mat> masks;
  std::vector<int> areas;
  for (size_t i = 0; i < anns.size(); ++i) {
    const CocoAnnotation& a = *anns[i];
    InstanceInfo info;
    info.id = static_cast<int>(i) + 1;
    info.label = CocoCategoryName(coco, a.category_id);
    info.score = a.score.value_or(1.0);
    out.instances.push_back(info);
    masks.push_back(CocoAnnotationMask(coco, a, image.height, image.width));
    areas.push_back(cv::countNonZero(masks.back()));
  }
  // Paint from the lowest priority to the highest; the last write wins.
  std::vector<size_t> order(anns.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const double sa = out.instances[a].score, sb = out.instances[b].score;
    if (sa != sb) return sa < sb;                          // higher score painted later
    if (areas[a] != areas[b]) return areas[a] > areas[b];  // smaller area later
    return a > b;                                          // earlier annotation later
  });
  for (size_t i : order) out.ids.setTo(cv::Scalar(out.instances[i].id), masks[i]);
  return out;
}

nlohmann::json CocoResultsFromInstanceMask(const InstanceMask& mask, int64_t image_id,
                                           const CocoFile& coco) {
  U4D_CHECK(mask.ids.type() == CV_16UC1 && !mask.ids.empty(),
            "CocoResultsFromInstanceMask: ids must be a non-empty CV_16UC1 image");
  json out = json::array();
  for (const InstanceInfo& info : mask.instances) {
    const cv::Mat binary = mask.ids == info.id;  // 255 / 0
    const int area = cv::countNonZero(binary);
    if (area == 0) continue;
    const CocoCategory* cat = nullptr;
    for (const CocoCategory& c : coco.categories)
      if (c.name == info.label) cat = &c;
    U4D_CHECK(cat != nullptr, "{}: no category named '{}' for instance {}", coco.context,
              info.label, info.id);
    const CocoRle rle = EncodeRle(binary);
    const cv::Rect box = cv::boundingRect(binary);
    out.push_back({{"image_id", image_id},
                   {"category_id", cat->id},
                   {"segmentation",
                    {{"size", {rle.height, rle.width}}, {"counts", CompressRleCounts(rle.counts)}}},
                   {"area", area},
                   // COCO boxes are [x, y, w, h] in corner-origin coordinates.
                   {"bbox", {box.x, box.y, box.width, box.height}},
                   {"score", info.score}});
  }
  return out;
}

}  // namespace u4d
