#include "u4d/io/coco.h"

#include <unistd.h>

#include <gtest/gtest.h>

#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

const fs::path kCocoJson = DataDir() / "coco_people" / "test_coco.json";

fs::path FreshDir(const std::string& name) { return test_util::FreshTestDir("coco_test", name); }

using test_util::ExpectErrorMentions;

double Perimeter(const std::vector<double>& xy) {
  double p = 0;
  const size_t n = xy.size() / 2;
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    p += std::hypot(xy[2 * j] - xy[2 * i], xy[2 * j + 1] - xy[2 * i + 1]);
  }
  return p;
}

TEST(Coco, RealPolygonAreasAgreeWithAreaField) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kCocoJson);
  const CocoFile coco = ReadCocoFile(kCocoJson);
  ASSERT_EQ(coco.images.size(), 4u);
  ASSERT_EQ(coco.annotations.size(), 14u);
  int checked = 0;
  for (const CocoAnnotation& a : coco.annotations) {
    const CocoImage& image = FindCocoImage(coco, a.image_id);
    ASSERT_FALSE(a.polygons.empty());
    const cv::Mat mask = CocoAnnotationMask(coco, a, image.height, image.width);
    ASSERT_EQ(mask.rows, image.height);
    ASSERT_EQ(mask.cols, image.width);
    const double raster = cv::countNonZero(mask);
    double perimeter = 0;
    for (const auto& poly : a.polygons) perimeter += Perimeter(poly);
    // COCO's "area" is the pixel count of its own rasteriser (pycocotools,
    // which walks the boundary on a 5x finer grid and rounds). Two
    // rasterisers of the same polygon can only disagree on pixels the boundary
    // passes through (about one per unit of perimeter), and then only where
    // their sub-pixel decisions differ, so we allow 0.1 pixel per unit of
    // perimeter (the largest seen is 0.054). A rasteriser that fills every
    // boundary pixel (cv::fillPoly) is off by about 0.45 per unit and fails.
    const double tol = 0.1 * perimeter;
    EXPECT_NEAR(raster, a.area, tol) << "annotation " << a.id << " perimeter " << perimeter;
    ++checked;
  }
  EXPECT_EQ(checked, 14);
}

TEST(Coco, RealInstanceMasksHaveImageSizeAndAllInstances) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kCocoJson);
  const CocoFile coco = ReadCocoFile(kCocoJson);
  for (const CocoImage& image : coco.images) {
    const InstanceMask mask = CocoInstanceMask(coco, FindCocoImage(coco, image.file_name));
    EXPECT_EQ(mask.ids.rows, image.height);
    EXPECT_EQ(mask.ids.cols, image.width);
    EXPECT_EQ(mask.ids.type(), CV_16UC1);
    const auto anns = SelectCocoAnnotations(coco, image);
    ASSERT_EQ(mask.instances.size(), anns.size());
    for (size_t i = 0; i < anns.size(); ++i) {
      const InstanceInfo& info = mask.instances[i];
      EXPECT_EQ(info.id, static_cast<int>(i) + 1);
      EXPECT_EQ(info.label, "person");
      EXPECT_EQ(info.score, 1.0);
      // Overlaps between COCO people are at most boundary slivers, so each
      // instance keeps at least 95 % of its annotated area.
      const int pixels = cv::countNonZero(mask.ids == info.id);
      EXPECT_GT(pixels, 0.95 * anns[i]->area) << image.file_name << " instance " << info.id;
    }
  }
  // The image with 5 people (000000196141.jpg) by file name; a path prefix
  // is ignored.
  EXPECT_EQ(
      CocoInstanceMask(coco, FindCocoImage(coco, "val2017/000000196141.jpg")).instances.size(), 5u);
}

TEST(Coco, HandComputedRleDecodes) {
  // 3 x 4 image, column-major runs: 1 background, 2 foreground, 3 background,
  // 4 foreground, 2 background.
  CocoRle rle{3, 4, {1, 2, 3, 4, 2}};
  const cv::Mat expected = (cv::Mat_<uint8_t>(3, 4) << 0, 0, 1, 1,  //
                            1, 0, 1, 0,                             //
                            1, 0, 1, 0);
  const cv::Mat decoded = DecodeRle(rle, "hand");
  EXPECT_EQ(cv::countNonZero(decoded != expected), 0);
  // Compressed: runs 0..2 as is ('1', '2', '3'), run 3 as 4 - 2 = 2 ('2'),
  // run 4 as 2 - 3 = -1 (5-bit group 31 with the sign bit, 31 + 48 = 'O').
  EXPECT_EQ(CompressRleCounts(rle.counts), "1232O");
  EXPECT_EQ(DecompressRleCounts("1232O", "hand"), rle.counts);
  // 100 = 3 * 32 + 4: group 4 with the continuation bit (36 + 48 = 'T'), then 3.
  EXPECT_EQ(CompressRleCounts({100}), "T3");
  EXPECT_EQ(DecompressRleCounts("T3", "hand"), std::vector<uint32_t>{100});
  // Encoding the expected mask gives the same runs back.
  EXPECT_EQ(EncodeRle(expected).counts, rle.counts);
}

TEST(Coco, RleRoundTripIsExact) {
  cv::RNG rng(7);
  std::vector<cv::Mat> masks;
  masks.push_back(cv::Mat::zeros(5, 7, CV_8UC1));
  masks.push_back(cv::Mat::ones(6, 3, CV_8UC1));
  for (int i = 0; i < 20; ++i) {
    cv::Mat m(rng.uniform(1, 60), rng.uniform(1, 60), CV_8UC1);
    rng.fill(m, cv::RNG::UNIFORM, 0, 2);
    masks.push_back(m);
  }
  // Real masks: long runs with large differences between them.
  U4D_SKIP_WITHOUT_SHARED_DATA(kCocoJson);
  const CocoFile coco = ReadCocoFile(kCocoJson);
  for (const CocoAnnotation& a : coco.annotations) {
    const CocoImage& im = FindCocoImage(coco, a.image_id);
    masks.push_back(CocoAnnotationMask(coco, a, im.height, im.width));
  }
  for (const cv::Mat& m : masks) {
    const CocoRle rle = EncodeRle(m);
    const std::string text = CompressRleCounts(rle.counts);
    const CocoRle back{rle.height, rle.width, DecompressRleCounts(text, "roundtrip")};
    EXPECT_EQ(back.counts, rle.counts);
    const cv::Mat decoded = DecodeRle(back, "roundtrip");
    EXPECT_EQ(cv::countNonZero((decoded != 0) != (m != 0)), 0);
  }
}

TEST(Coco, SquarePolygonCoversExactlyItsPixels) {
  // COCO corner-origin square [1, 4] x [2, 5] covers pixels columns 1..3 and
  // rows 2..4 (their centres 1.5..3.5 / 2.5..4.5 in COCO coordinates).
  const cv::Mat m = RasterizeCocoPolygons({{1, 2, 4, 2, 4, 5, 1, 5}}, 8, 8, "square");
  EXPECT_EQ(cv::countNonZero(m), 9);
  EXPECT_EQ(cv::countNonZero(m(cv::Rect(1, 2, 3, 3))), 9);
  // Two overlapping parts unite (not even-odd).
  const cv::Mat u =
      RasterizeCocoPolygons({{0, 0, 4, 0, 4, 4, 0, 4}, {2, 2, 6, 2, 6, 6, 2, 6}}, 8, 8, "union");
  EXPECT_EQ(cv::countNonZero(u), 16 + 16 - 4);
}

TEST(Coco, OverlapRuleHigherScoreThenSmallerArea) {
  CocoFile coco;
  coco.context = "synthetic";
  coco.images = {{1, "a.png", 10, 10}};
  coco.categories = {{1, "person"}};
  CocoAnnotation big;
  big.image_id = 1;
  big.category_id = 1;
  big.polygons = {{0, 0, 8, 0, 8, 8, 0, 8}};  // 64 px
  CocoAnnotation small = big;
  small.polygons = {{2, 2, 4, 2, 4, 4, 2, 4}};  // 4 px inside big
  // Equal scores: the smaller one stays on top whatever the order.
  coco.annotations = {big, small};
  InstanceMask m = CocoInstanceMask(coco, coco.images[0]);
  EXPECT_EQ(m.ids.at<uint16_t>(3, 3), 2);
  EXPECT_EQ(cv::countNonZero(m.ids == 1), 60);
  coco.annotations = {small, big};
  m = CocoInstanceMask(coco, coco.images[0]);
  EXPECT_EQ(m.ids.at<uint16_t>(3, 3), 1);
  EXPECT_EQ(cv::countNonZero(m.ids == 2), 60);
  // A higher score wins over a smaller area.
  coco.annotations[0].score = 0.5;
  coco.annotations[1].score = 0.9;
  m = CocoInstanceMask(coco, coco.images[0]);
  EXPECT_EQ(cv::countNonZero(m.ids == 1), 0);
  EXPECT_EQ(cv::countNonZero(m.ids == 2), 64);
  EXPECT_DOUBLE_EQ(m.instances[0].score, 0.5);
  // min_score drops the weak one; ids are renumbered 1..N.
  CocoMaskOptions opt;
  opt.min_score = 0.6;
  m = CocoInstanceMask(coco, coco.images[0], opt);
  ASSERT_EQ(m.instances.size(), 1u);
  EXPECT_EQ(cv::countNonZero(m.ids == 1), 64);
}

// category_id -> the category's name: the class every later stage carries
// (docs/formats.md); a category filter keeps one class.
TEST(Coco, CategoryIdsBecomeClassNames) {
  CocoFile coco;
  coco.context = "synthetic";
  coco.images = {{1, "a.png", 10, 10}};
  coco.categories = {{1, "person"}, {44, "bottle"}};
  CocoAnnotation person;
  person.image_id = 1;
  person.category_id = 1;
  person.polygons = {{0, 0, 4, 0, 4, 8, 0, 8}};
  CocoAnnotation bottle = person;
  bottle.category_id = 44;
  bottle.polygons = {{6, 2, 8, 2, 8, 6, 6, 6}};
  coco.annotations = {person, bottle};
  const InstanceMask m = CocoInstanceMask(coco, coco.images[0]);
  ASSERT_EQ(m.instances.size(), 2u);
  EXPECT_EQ(m.instances[0].label, "person");
  EXPECT_EQ(m.instances[1].label, "bottle");
  EXPECT_EQ(cv::countNonZero(m.ids == 2), 8);
  CocoMaskOptions only;
  only.category = "bottle";
  const InstanceMask b = CocoInstanceMask(coco, coco.images[0], only);
  ASSERT_EQ(b.instances.size(), 1u);
  EXPECT_EQ(b.instances[0].label, "bottle");
}

TEST(Coco, ResultsRoundTripThroughCompressedRle) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kCocoJson);
  const CocoFile coco = ReadCocoFile(kCocoJson);
  const CocoImage& image = FindCocoImage(coco, "000000197388.jpg");
  InstanceMask mask = CocoInstanceMask(coco, image);
  for (size_t i = 0; i < mask.instances.size(); ++i) mask.instances[i].score = 0.5 + 0.1 * i;
  const fs::path path = FreshDir("results") / "results.json";
  WriteJsonFileAtomic(path, CocoResultsFromInstanceMask(mask, image.id, coco));
  const CocoFile results = ReadCocoResults(path, coco);
  ASSERT_EQ(results.annotations.size(), mask.instances.size());
  for (const CocoAnnotation& a : results.annotations) {
    ASSERT_TRUE(a.rle.has_value());
    ASSERT_TRUE(a.score.has_value());
  }
  const InstanceMask back = CocoInstanceMask(results, FindCocoImage(results, image.id));
  EXPECT_EQ(cv::countNonZero(back.ids != mask.ids), 0);
  for (size_t i = 0; i < mask.instances.size(); ++i)
    EXPECT_NEAR(back.instances[i].score, mask.instances[i].score, 1e-12);
}

TEST(Coco, UncompressedRleSegmentation) {
  const nlohmann::json j = {
      {"images", {{{"id", 5}, {"file_name", "x.png"}, {"width", 4}, {"height", 3}}}},
      {"categories", {{{"id", 1}, {"name", "person"}}}},
      {"annotations",
       {{{"id", 9},
         {"image_id", 5},
         {"category_id", 1},
         {"iscrowd", 0},
         {"segmentation", {{"size", {3, 4}}, {"counts", {1, 2, 3, 4, 2}}}}}}}};
  const CocoFile coco = ParseCoco(j, "inline");
  const InstanceMask m = CocoInstanceMask(coco, FindCocoImage(coco, "x.png"));
  EXPECT_EQ(cv::countNonZero(m.ids), 6);
  EXPECT_EQ(m.ids.at<uint16_t>(1, 0), 1);
  EXPECT_EQ(m.ids.at<uint16_t>(0, 3), 1);
  EXPECT_EQ(m.ids.at<uint16_t>(0, 0), 0);
}

TEST(Coco, BadInputsNameTheFile) {
  const fs::path dir = FreshDir("bad");
  ExpectErrorMentions([&] { ReadCocoFile(dir / "missing.json"); }, {"missing.json"});
  U4D_SKIP_WITHOUT_SHARED_DATA(kCocoJson);
  const CocoFile coco = ReadCocoFile(kCocoJson);
  ExpectErrorMentions([&] { FindCocoImage(coco, "nope.jpg"); }, {"test_coco.json", "nope.jpg"});
  ExpectErrorMentions([&] { FindCocoImage(coco, int64_t{12345}); }, {"test_coco.json", "12345"});

  const auto write = [&](const std::string& name, const nlohmann::json& seg) {
    const nlohmann::json j = {
        {"images", {{{"id", 5}, {"file_name", "x.png"}, {"width", 4}, {"height", 3}}}},
        {"categories", {{{"id", 1}, {"name", "person"}}}},
        {"annotations", {{{"id", 9}, {"image_id", 5}, {"category_id", 1}, {"segmentation", seg}}}}};
    WriteJsonFileAtomic(dir / name, j);
    return dir / name;
  };
  // Counts not summing to h * w.
  const fs::path short_counts = write("short.json", {{"size", {3, 4}}, {"counts", {1, 2, 3}}});
  ExpectErrorMentions([&] { ReadCocoFile(short_counts); }, {"short.json", "sum to 6"});
  // Bad size.
  const fs::path neg = write("neg.json", {{"size", {-3, 4}}, {"counts", {12}}});
  ExpectErrorMentions([&] { ReadCocoFile(neg); }, {"neg.json", "size"});
  // A valid RLE of another size than the image.
  const fs::path other = write("other.json", {{"size", {4, 3}}, {"counts", {12}}});
  const CocoFile o = ReadCocoFile(other);
  ExpectErrorMentions([&] { CocoInstanceMask(o, o.images[0]); }, {"other.json", "differs"});
  // Garbage in a compressed string.
  const fs::path garbage = write("garbage.json", {{"size", {3, 4}}, {"counts", "12\x7f"}});
  ExpectErrorMentions([&] { ReadCocoFile(garbage); }, {"garbage.json", "alphabet"});
  // Odd polygon length.
  const fs::path odd = write("odd.json", {{0, 0, 1, 0, 1}});
  ExpectErrorMentions([&] { ReadCocoFile(odd); }, {"odd.json", "polygon"});
  // Malformed JSON.
  WriteTextFileAtomic(dir / "broken.json", "{\"images\": [");
  ExpectErrorMentions([&] { ReadCocoFile(dir / "broken.json"); }, {"broken.json"});
}

}  // namespace
}  // namespace u4d
