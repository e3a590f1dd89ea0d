#include "u4d/synth/bvh.h"

#include <cctype>
#include <charconv>
#include <cmath>

#include <Eigen/Geometry>

#include "u4d/util/check.h"

namespace u4d::synth {
namespace {

// Splits text into whitespace-separated tokens, remembering the line of each.
class Tokenizer {
 public:
  Tokenizer(const std::string& text, const std::string& source) : text_(text), source_(source) {}

  bool AtEnd() {
    SkipSpace();
    return pos_ >= text_.size();
  }
  int line() const { return line_; }

  std::string_view Next(const char* expected) {
    SkipSpace();
    U4D_CHECK(pos_ < text_.size(), "{}: unexpected end of file, expected {}", source_, expected);
    const size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    return std::string_view(text_).substr(start, pos_ - start);
  }

  void Expect(std::string_view word) {
    const std::string_view got = Next(std::string(word).c_str());
    U4D_CHECK(got == word, "{}:{}: expected '{}', found '{}'", source_, line_, word, got);
  }

  double Number(const char* what) {
    const std::string_view tok = Next(what);
    double value = 0;
    const char* end = tok.data() + tok.size();
    auto [ptr, ec] = std::from_chars(tok.data(), end, value);
    U4D_CHECK(ec == std::errc() && ptr == end, "{}:{}: expected a number ({}), found '{}'", source_,
              line_, what, tok);
    U4D_CHECK(std::isfinite(value), "{}:{}: non-finite number ({}) '{}'", source_, line_, what,
              tok);
    return value;
  }

  int Integer(const char* what) {
    const std::string_view tok = Next(what);
    int value = 0;
    const char* end = tok.data() + tok.size();
    auto [ptr, ec] = std::from_chars(tok.data(), end, value);
    U4D_CHECK(ec == std::errc() && ptr == end, "{}:{}: expected an integer ({}), found '{}'",
              source_, line_, what, tok);
    return value;
  }

 private:
  void SkipSpace() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }

  const std::string& text_;
  const std::string& source_;
  size_t pos_ = 0;
  int line_ = 1;
};

BvhChannel ParseChannel(std::string_view name, const Tokenizer& tok, const std::string& source) {
  if (name == "Xposition") return BvhChannel::kXposition;
  if (name == "Yposition") return BvhChannel::kYposition;
  if (name == "Zposition") return BvhChannel::kZposition;
  if (name == "Xrotation") return BvhChannel::kXrotation;
  if (name == "Yrotation") return BvhChannel::kYrotation;
  if (name == "Zrotation") return BvhChannel::kZrotation;
  ThrowError(fmt::format("{}:{}: unknown channel name '{}'", source, tok.line(), name));
}

// Parses the body of a JOINT/ROOT block after its name, recursively.
void ParseJoint(Tokenizer& tok, const std::string& source, int parent, std::string name,
                BvhMotion* motion) {
  const int index = static_cast<int>(motion->joints.size());
  {
    BvhJoint joint;
    joint.name = std::move(name);
    joint.parent = parent;
    motion->joints.push_back(std::move(joint));
  }
  tok.Expect("{");
  tok.Expect("OFFSET");
  Eigen::Vector3d offset;
  for (int i = 0; i < 3; ++i) offset[i] = tok.Number("OFFSET value");
  motion->joints[index].offset = offset;
  while (true) {
    const std::string_view word = tok.Next("CHANNELS, JOINT, End Site or '}'");
    if (word == "}") break;
    if (word == "CHANNELS") {
      const int n = tok.Integer("channel count");
      U4D_CHECK(n >= 0 && n <= 6, "{}:{}: channel count {} out of range 0..6", source, tok.line(),
                n);
      BvhJoint& joint = motion->joints[index];
      U4D_CHECK(joint.channels.empty(), "{}:{}: joint '{}' has two CHANNELS lines", source,
                tok.line(), joint.name);
      joint.first_channel = motion->num_channels;
      for (int i = 0; i < n; ++i) {
        const std::string_view ch = tok.Next("channel name");
        joint.channels.push_back(ParseChannel(ch, tok, source));
      }
      motion->num_channels += n;
    } else if (word == "JOINT") {
      std::string child_name(tok.Next("joint name"));
      ParseJoint(tok, source, index, std::move(child_name), motion);
    } else if (word == "End") {
      tok.Expect("Site");
      BvhJoint end;
      end.name = motion->joints[index].name + "_End";
      end.parent = index;
      end.end_site = true;
      end.first_channel = motion->num_channels;
      tok.Expect("{");
      tok.Expect("OFFSET");
      for (int i = 0; i < 3; ++i) end.offset[i] = tok.Number("End Site OFFSET value");
      tok.Expect("}");
      motion->joints.push_back(std::move(end));
    } else {
      ThrowError(fmt::format("{}:{}: unexpected '{}' in joint '{}'", source, tok.line(), word,
                             motion->joints[index].name));
    }
  }
}

Eigen::Matrix3d AxisRotation(BvhChannel c, double degrees) {
  const double a = degrees * M_PI / 180.0;
  switch (c) {
    case BvhChannel::kXrotation:
      return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
    case BvhChannel::kYrotation:
      return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
    case BvhChannel::kZrotation:
      return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    default:
      return Eigen::Matrix3d::Identity();
  }
}

std::vector<Rigid3d> Fk(const BvhMotion& motion, const double* row) {
  std::vector<Rigid3d> world(motion.joints.size());
  for (size_t j = 0; j < motion.joints.size(); ++j) {
    const BvhJoint& joint = motion.joints[j];
    Rigid3d parent_from_joint;
    parent_from_joint.translation = joint.offset;
    if (row != nullptr) {
      for (size_t c = 0; c < joint.channels.size(); ++c) {
        const double v = row[joint.first_channel + c];
        switch (joint.channels[c]) {
          case BvhChannel::kXposition:
            parent_from_joint.translation.x() += v;
            break;
          case BvhChannel::kYposition:
            parent_from_joint.translation.y() += v;
            break;
          case BvhChannel::kZposition:
            parent_from_joint.translation.z() += v;
            break;
          default:
            parent_from_joint.rotation =
                parent_from_joint.rotation * AxisRotation(joint.channels[c], v);
        }
      }
    }
    world[j] = joint.parent < 0 ? parent_from_joint : world[joint.parent] * parent_from_joint;
  }
  return world;
}

}  // namespace

BvhMotion ParseBvh(const std::string& text, const std::string& source) {
  BvhMotion motion;
  motion.source = source;
  Tokenizer tok(text, source);
  tok.Expect("HIERARCHY");
  tok.Expect("ROOT");
  std::string root_name(tok.Next("root joint name"));
  ParseJoint(tok, source, -1, std::move(root_name), &motion);
  const std::string_view word = tok.Next("MOTION");
  U4D_CHECK(word == "MOTION",
            "{}:{}: expected MOTION after the hierarchy (only one ROOT is "
            "supported), found '{}'",
            source, tok.line(), word);
  tok.Expect("Frames:");
  motion.num_frames = tok.Integer("frame count");
  U4D_CHECK(motion.num_frames > 0, "{}:{}: frame count must be positive, found {}", source,
            tok.line(), motion.num_frames);
  tok.Expect("Frame");
  tok.Expect("Time:");
  motion.frame_time = tok.Number("frame time");
  U4D_CHECK(motion.frame_time > 0, "{}:{}: frame time must be positive, found {}", source,
            tok.line(), motion.frame_time);
  motion.values.resize(motion.num_frames, motion.num_channels);
  for (int f = 0; f < motion.num_frames; ++f) {
    for (int c = 0; c < motion.num_channels; ++c) {
      U4D_CHECK(!tok.AtEnd(),
                "{}: truncated motion data: frame {} of {} has only {} of {} channel values "
                "(expected {} numbers in all)",
                source, f, motion.num_frames, c, motion.num_channels,
                static_cast<int64_t>(motion.num_frames) * motion.num_channels);
      motion.values(f, c) = tok.Number("motion value");
    }
  }
  U4D_CHECK(tok.AtEnd(), "{}:{}: extra data after the {} frames announced in the header", source,
            tok.line(), motion.num_frames);
  return motion;
}

BvhMotion ReadBvh(const fs::path& path) {
  CheckFileExists(path, "BVH file");
  return ParseBvh(ReadTextFile(path), path.string());
}

int FindBvhJoint(const BvhMotion& motion, const std::string& name) {
  for (size_t j = 0; j < motion.joints.size(); ++j) {
    if (motion.joints[j].name == name) return static_cast<int>(j);
  }
  return -1;
}

std::vector<Rigid3d> BvhForwardKinematics(const BvhMotion& motion, int frame) {
  U4D_CHECK(frame >= 0 && frame < motion.num_frames, "{}: frame {} out of range 0..{}",
            motion.source, frame, motion.num_frames - 1);
  const Eigen::VectorXd row = motion.values.row(frame).transpose();
  return Fk(motion, row.data());
}

std::vector<Rigid3d> BvhRestPose(const BvhMotion& motion) { return Fk(motion, nullptr); }

}  // namespace u4d::synth
