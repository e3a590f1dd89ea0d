#include "u4d/io/image_io.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d {
namespace {

// Big-endian 32-bit at `p`.
uint32_t ReadBigEndian32(const unsigned char* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}

const char* FormatName(ImageFormat format) {
  switch (format) {
    case ImageFormat::kPng:
      return "PNG";
    case ImageFormat::kJpeg:
      return "JPEG";
    case ImageFormat::kBmp:
      return "BMP";
    case ImageFormat::kTiff:
      return "TIFF";
    case ImageFormat::kUnknown:
      break;
  }
  return "unknown";
}

// The first bytes of a file (fewer when it is shorter): enough for the
// format's signature and a PNG's IHDR.
std::string FileHeader(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string header(24, '\0');
  in.read(header.data(), static_cast<std::streamsize>(header.size()));
  header.resize(static_cast<size_t>(in.gcount()));
  return header;
}

ImageFormat FormatOfHeader(const std::string& header) {
  const auto starts = [&](std::initializer_list<unsigned char> magic) {
    return header.size() >= magic.size() &&
           std::equal(magic.begin(), magic.end(), header.begin(),
                      [](unsigned char a, char b) { return a == static_cast<unsigned char>(b); });
  };
  if (starts({0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A})) return ImageFormat::kPng;
  if (starts({0xFF, 0xD8, 0xFF})) return ImageFormat::kJpeg;
  if (starts({'B', 'M'})) return ImageFormat::kBmp;
  if (starts({'I', 'I', 42, 0}) || starts({'M', 'M', 0, 42})) return ImageFormat::kTiff;
  return ImageFormat::kUnknown;
}

// The PNG header (IHDR, bytes 16-23) gives the size before anything is decoded.
void CheckPngSize(const fs::path& path, const std::string& header_bytes, const char* what) {
  const auto* header = reinterpret_cast<const unsigned char*>(header_bytes.data());
  U4D_CHECK(header_bytes.size() == 24 && std::memcmp(header + 12, "IHDR", 4) == 0,
            "{}: corrupt {} (PNG without an IHDR header)", path.string(), what);
  const int64_t width = ReadBigEndian32(header + 16), height = ReadBigEndian32(header + 20);
  U4D_CHECK(width > 0 && height > 0 && height <= kMaxImagePixels / width,
            "{}: implausible {} size {}x{} (at most {} pixels)", path.string(), what, width, height,
            kMaxImagePixels);
}

// Decodes `path` when its format is one of `allowed`, else throws naming the file.
cv::Mat ReadAny(const fs::path& path, int flags, const char* what,
                std::initializer_list<ImageFormat> allowed) {
  CheckFileExists(path, what);
  const std::string header = FileHeader(path);
  const ImageFormat format = FormatOfHeader(header);
  const bool ok = std::find(allowed.begin(), allowed.end(), format) != allowed.end();
  std::string names;
  for (ImageFormat f : allowed) names += std::string(names.empty() ? "" : ", ") + FormatName(f);
  U4D_CHECK(ok, "{}: {} is corrupt or in a format not read here (found {}, expected {})",
            path.string(), what, FormatName(format), names);
  if (format == ImageFormat::kPng) CheckPngSize(path, header, what);
  cv::Mat image = cv::imread(path.string(), flags);
  U4D_CHECK(!image.empty(), "{}: cannot decode {} (corrupt {})", path.string(), what,
            FormatName(format));
  return image;
}

// Checks, before anything is allocated, that the file holds at least
// `data_bytes` after its `header_bytes`-byte header.
void CheckDataSize(const fs::path& path, uint64_t header_bytes, uint64_t data_bytes,
                   const std::string& what) {
  std::error_code ec;
  const uint64_t size = fs::file_size(path, ec);
  U4D_CHECK(!ec, "{}: cannot read the file size: {}", path.string(), ec.message());
  U4D_CHECK(size >= header_bytes && size - header_bytes >= data_bytes,
            "{}: truncated file: the header announces {} ({} bytes) but {} bytes follow it",
            path.string(), what, data_bytes, size >= header_bytes ? size - header_bytes : 0);
}

}  // namespace

ImageFormat SniffImageFormat(const fs::path& path) { return FormatOfHeader(FileHeader(path)); }

cv::Mat ReadColorImage(const fs::path& path) {
  cv::Mat image =
      ReadAny(path, cv::IMREAD_COLOR, "image",
              {ImageFormat::kPng, ImageFormat::kJpeg, ImageFormat::kBmp, ImageFormat::kTiff});
  U4D_CHECK(image.depth() == CV_8U, "{}: expected an 8-bit image", path.string());
  return image;
}

cv::Mat ReadLabelImage(const fs::path& path) {
  cv::Mat image = ReadAny(path, cv::IMREAD_UNCHANGED, "label image", {ImageFormat::kPng});
  U4D_CHECK(image.channels() == 1, "{}: label image must have one channel, found {}", path.string(),
            image.channels());
  U4D_CHECK(image.depth() == CV_16U || image.depth() == CV_8U,
            "{}: label image must be 8- or 16-bit unsigned", path.string());
  if (image.depth() == CV_8U) image.convertTo(image, CV_16U);
  return image;
}

cv::Mat ReadMaskImage(const fs::path& path) {
  cv::Mat image = ReadAny(path, cv::IMREAD_GRAYSCALE, "mask image", {ImageFormat::kPng});
  return image > 0;
}

void WriteImage(const fs::path& path, const cv::Mat& image) {
  U4D_CHECK(!image.empty(), "refusing to write an empty image to {}", path.string());
  WriteAtomically(path, [&](const fs::path& tmp) {
    U4D_CHECK(cv::imwrite(tmp.string(), image), "cannot write image {}", path.string());
  });
}

cv::Mat ReadPfm(const fs::path& path) {
  CheckFileExists(path, "PFM file");
  std::ifstream in(path, std::ios::binary);
  std::string magic;
  int width = 0, height = 0;
  double scale = 0;
  in >> magic >> width >> height >> scale;
  U4D_CHECK(in.good() && (magic == "Pf" || magic == "PF"),
            "{}: not a PFM file (expected header 'Pf' or 'PF')", path.string());
  U4D_CHECK(width > 0 && height > 0 && width < 100000 && height < 100000,
            "{}: implausible PFM size {}x{}", path.string(), width, height);
  U4D_CHECK(scale != 0 && std::isfinite(scale), "{}: invalid PFM scale", path.string());
  in.get();  // the single whitespace byte after the header
  const int channels = magic == "PF" ? 3 : 1;
  const size_t row_bytes = static_cast<size_t>(width) * channels * sizeof(float);
  CheckDataSize(path, static_cast<uint64_t>(in.tellg()), row_bytes * height,
                fmt::format("PFM data for {}x{}x{} floats", width, height, channels));
  cv::Mat image(height, width, CV_32FC(channels));
  // PFM stores rows bottom to top.
  for (int y = height - 1; y >= 0; --y) {
    in.read(reinterpret_cast<char*>(image.ptr(y)), static_cast<std::streamsize>(row_bytes));
    U4D_CHECK(in.gcount() == static_cast<std::streamsize>(row_bytes),
              "{}: truncated PFM data (expected {}x{}x{} floats)", path.string(), width, height,
              channels);
  }
  if (scale > 0) {  // big-endian: swap bytes
    for (int y = 0; y < height; ++y) {
      auto* bytes = reinterpret_cast<uint8_t*>(image.ptr(y));
      for (size_t i = 0; i + 3 < row_bytes; i += 4) {
        std::swap(bytes[i], bytes[i + 3]);
        std::swap(bytes[i + 1], bytes[i + 2]);
      }
    }
  }
  if (channels == 3) cv::cvtColor(image, image, cv::COLOR_RGB2BGR);
  return image;
}

void WritePfm(const fs::path& path, const cv::Mat& image_in) {
  U4D_CHECK(image_in.depth() == CV_32F && (image_in.channels() == 1 || image_in.channels() == 3),
            "WritePfm({}): expected a float image with 1 or 3 channels", path.string());
  cv::Mat image = image_in;
  if (image.channels() == 3) cv::cvtColor(image_in, image, cv::COLOR_BGR2RGB);
  WriteAtomically(path, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    U4D_CHECK(out.good(), "cannot open {} for writing", tmp.string());
    out << (image.channels() == 3 ? "PF" : "Pf") << "\n"
        << image.cols << " " << image.rows << "\n-1\n";
    const size_t row_bytes = static_cast<size_t>(image.cols) * image.channels() * sizeof(float);
    for (int y = image.rows - 1; y >= 0; --y)
      out.write(reinterpret_cast<const char*>(image.ptr(y)),
                static_cast<std::streamsize>(row_bytes));
    U4D_CHECK(out.good(), "failed writing {}", tmp.string());
  });
}

cv::Mat ReadFlo(const fs::path& path) {
  CheckFileExists(path, "flow file");
  std::ifstream in(path, std::ios::binary);
  float magic = 0;
  int32_t width = 0, height = 0;
  in.read(reinterpret_cast<char*>(&magic), 4);
  in.read(reinterpret_cast<char*>(&width), 4);
  in.read(reinterpret_cast<char*>(&height), 4);
  U4D_CHECK(in.good() && magic == 202021.25f,
            "{}: not a .flo file (magic number 202021.25 missing)", path.string());
  U4D_CHECK(width > 0 && height > 0 && width < 100000 && height < 100000,
            "{}: implausible flow size {}x{}", path.string(), width, height);
  const std::streamsize bytes = static_cast<std::streamsize>(width) * height * 2 * sizeof(float);
  CheckDataSize(path, 12, static_cast<uint64_t>(bytes),
                fmt::format("flow data for {}x{} vectors", width, height));
  cv::Mat flow(height, width, CV_32FC2);
  in.read(reinterpret_cast<char*>(flow.data), bytes);
  U4D_CHECK(in.gcount() == bytes, "{}: truncated flow data (expected {}x{} vectors)", path.string(),
            width, height);
  return flow;
}

void WriteFlo(const fs::path& path, const cv::Mat& flow) {
  U4D_CHECK(flow.type() == CV_32FC2, "WriteFlo({}): expected CV_32FC2", path.string());
  cv::Mat contiguous = flow.isContinuous() ? flow : flow.clone();
  WriteAtomically(path, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    U4D_CHECK(out.good(), "cannot open {} for writing", tmp.string());
    const float magic = 202021.25f;
    const int32_t width = contiguous.cols, height = contiguous.rows;
    out.write(reinterpret_cast<const char*>(&magic), 4);
    out.write(reinterpret_cast<const char*>(&width), 4);
    out.write(reinterpret_cast<const char*>(&height), 4);
    out.write(reinterpret_cast<const char*>(contiguous.data),
              static_cast<std::streamsize>(contiguous.total() * contiguous.elemSize()));
    U4D_CHECK(out.good(), "failed writing {}", tmp.string());
  });
}

void CheckImageSize(const cv::Mat& image, int width, int height, const std::string& what) {
  U4D_CHECK(image.cols == width && image.rows == height, "{}: expected size {}x{}, found {}x{}",
            what, width, height, image.cols, image.rows);
}

}  // namespace u4d
