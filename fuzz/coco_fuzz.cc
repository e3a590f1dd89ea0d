// A COCO file (io/coco.h): dataset or results, then every annotation's mask
// (polygons rasterised, RLE decoded) for images of at most a million pixels
// (a file may well describe larger images; the fuzzer's memory is bounded).
#include "fuzz_input.h"
#include "u4d/io/coco.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  const fs::path path = fuzz::WriteInput("coco.json", data, size);
  fuzz::AcceptErrors([&] {
    const CocoFile coco = ReadCocoFile(path);
    for (const CocoAnnotation& a : coco.annotations) {
      fuzz::AcceptErrors([&] {
        const CocoImage& image = FindCocoImage(coco, a.image_id);
        if (int64_t(image.width) * image.height <= 1000000)
          CocoAnnotationMask(coco, a, image.height, image.width);
      });
    }
  });
  return 0;
}
