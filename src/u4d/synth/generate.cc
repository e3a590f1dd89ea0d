#include "u4d/synth/generate.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <random>

#include <unistd.h>

#include <open3d/geometry/TriangleMesh.h>
#include <open3d/io/TriangleMeshIO.h>
#include <tbb/parallel_for.h>
#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>

#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/poses.h"
#include "u4d/synth/contact.h"
#include "u4d/synth/people.h"
#include "u4d/synth/texture.h"
#include "u4d/util/check.h"
#include "u4d/util/progress.h"
#include "u4d/util/timer.h"

namespace u4d::synth {

namespace {

// The presets whose people are all captured performers.
bool IsRealistic(const std::string& preset) {
  return preset == "realistic" || preset == "realistic-moving";
}

// The realistic presets' world (generate.h).
void SetRealistic(SynthOptions* o) {
  o->environment.indoor = true;
  o->script_seconds = 1.0;  // no procedural people: the script is empty
  o->masks = MaskDegradeOptions::Realistic();
  o->render.noise_sigma = 2.5f;
  o->render.gain_jitter = 0.08f;
  o->effects.motion_blur_shutter = 0.5;
  o->effects.shadow_strength = 0.45;
  CapturedPerformerOptions dance;
  dance.source = "pdance/frames";
  dance.stature = 1.72;
  dance.position = {-0.6, 0.0};
  dance.yaw = 0.4;
  dance.appearance_seed = 3;
  CapturedPerformerOptions jump;
  jump.source = "pjump/pjump_positions.pc2";
  jump.source_has_head = false;
  jump.stature = 1.80;
  jump.position = {0.6, 0.1};
  jump.yaw = -2.2;
  jump.appearance_seed = 4;
  o->captured = {dance, jump};
  o->captured_touch_gap = 0.02;
}

}  // namespace

const std::vector<std::string>& SynthPresetNames() {
  static const std::vector<std::string> names = {"handshake", "meetup",           "moving-cameras",
                                                 "realistic", "realistic-moving", "objects"};
  return names;
}

SynthOptions SynthPreset(const std::string& preset) {
  SynthOptions o;
  o.preset = preset;
  if (preset == "handshake") {
    o.environment.indoor = true;
  } else if (preset == "meetup") {
    o.environment.indoor = false;
    o.num_people = 3;
    o.num_frames = 100;
    o.script_seconds = 8.0;
    o.rig.radius = 5.5;
  } else if (preset == "moving-cameras") {
    o.environment.indoor = true;
    o.rig.angular_speed_deg_per_s = 12.0;
    o.rig.bob_amplitude = 0.1;
  } else if (preset == "objects") {
    o.environment.indoor = true;
    o.props = PropsFromNames({"box", "ball"});
  } else if (IsRealistic(preset)) {
    SetRealistic(&o);
    if (preset == "realistic-moving") {
      o.rig.angular_speed_deg_per_s = 12.0;
      o.rig.bob_amplitude = 0.1;
    }
  } else {
    std::string known;
    for (const auto& n : SynthPresetNames()) known += (known.empty() ? "" : ", ") + n;
    ThrowError(fmt::format("unknown synthetic preset '{}' (known: {})", preset, known));
  }
  o.environment.seed = static_cast<uint32_t>(o.seed * 7919u + 17u);
  return o;
}

void SynthOptions::Check() const {
  const auto& names = SynthPresetNames();
  U4D_CHECK(std::find(names.begin(), names.end(), preset) != names.end(),
            "unknown synthetic preset '{}'", preset);
  U4D_CHECK(num_frames >= 2, "synth: num_frames must be at least 2, got {}", num_frames);
  U4D_CHECK(fps > 0 && std::isfinite(fps), "synth: fps must be positive, got {}", fps);
  U4D_CHECK(preset != "meetup" || num_people >= 3, "synth: meetup needs >= 3 people, got {}",
            num_people);
  U4D_CHECK(preset != "meetup" || !mocap_bvh.empty(),
            "synth: the meetup preset needs a BVH clip (mocap_bvh)");
  U4D_CHECK(script_seconds > 0 && std::isfinite(script_seconds),
            "synth: script_seconds must be positive, got {}", script_seconds);
  U4D_CHECK(png_compression >= 0 && png_compression <= 9, "synth: png_compression must be 0-9");
  U4D_CHECK(clean_plate_frames >= 0, "synth: clean_plate_frames must be >= 0, got {}",
            clean_plate_frames);
  U4D_CHECK(clean_plate_frames == 0 || !rig.IsMoving(),
            "synth: a clean plate needs a static rig (the '{}' rig moves)", preset);
  rig.Check();
  environment.Check();
  render.Check();
  flow.Check();
  masks.Check();
  keypoints.Check();
  effects.Check();
  for (const CapturedPerformerOptions& c : captured) c.Check();
  for (const PropOptions& p : props) p.Check();
  U4D_CHECK(std::isfinite(captured_touch_gap), "synth: captured_touch_gap must be finite");
  U4D_CHECK(captured.empty() || !captured_meshes.empty() ||
                std::all_of(captured.begin(), captured.end(),
                            [](const auto& c) { return c.source.is_absolute(); }),
            "synth: the '{}' preset reads captured mesh sequences: give their folder "
            "(captured_meshes)",
            preset);
}

namespace {

PeopleScript MakeScript(const SynthOptions& o, int script_frames) {
  if (o.preset == "meetup")
    return MakeMeetupScript(o.num_people, script_frames, o.fps, o.seed, o.mocap_bvh);
  if (IsRealistic(o.preset)) {
    PeopleScript empty;
    empty.fps = o.fps;
    empty.num_frames = script_frames;
    return empty;
  }
  return MakeHandshakeScript(script_frames, o.fps, o.seed);
}

// The captured performers of the capture, loaded and placed.
std::vector<CapturedPerformer> LoadCaptured(const SynthOptions& o) {
  // The seed varies the performance as it varies the procedural people: each
  // performer starts at another source frame, and the group turns about the
  // origin.
  std::mt19937_64 rng(o.seed * 0x9E3779B97F4A7C15ULL + 0x7f4a7c15ULL);
  const double turn = std::uniform_real_distribution<double>(0, 2 * M_PI)(rng);
  const Eigen::Rotation2Dd rotate(-turn);  // about +y, as seen in the (x, z) plane
  std::vector<CapturedPerformerOptions> specs = o.captured;
  std::vector<CapturedPerformer> performers;
  for (CapturedPerformerOptions& c : specs) {
    if (c.source.is_relative()) c.source = o.captured_meshes / c.source;
    c.first_frame += static_cast<int>(rng() % 100);
    c.position = rotate * c.position;
    c.yaw += turn;
    performers.push_back(LoadCapturedPerformer(c, o.num_frames));
  }
  if (performers.size() >= 2 && o.captured_touch_gap >= 0) {
    const Eigen::Vector2d line = specs[1].position - specs[0].position;
    const Eigen::Vector2d direction =
        line.norm() > 1e-9 ? Eigen::Vector2d(line.normalized()) : Eigen::Vector2d(1, 0);
    PlaceAtClosestApproach(performers[0], &performers[1], direction, o.captured_touch_gap,
                           o.num_frames);
  }
  return performers;
}

// First script frame of the capture window (see SynthOptions::start_frame).
int WindowStart(const SynthOptions& o, const PeopleScript& script) {
  const int last_start = script.num_frames - o.num_frames;
  if (o.start_frame >= 0) {
    U4D_CHECK(o.start_frame <= last_start,
              "synth: start_frame {} + num_frames {} exceeds the script's {} frames", o.start_frame,
              o.num_frames, script.num_frames);
    return o.start_frame;
  }
  if (script.handshakes.empty()) return 0;
  const HandshakeEvent& h = script.handshakes.front();
  const int centre = static_cast<int>(std::lround(0.5 * (h.shake_start + h.shake_end) * o.fps));
  return std::clamp(centre - o.num_frames / 2, 0, last_start);
}

void WritePng(const fs::path& path, const cv::Mat& image, int compression) {
  WriteAtomically(path, [&](const fs::path& tmp) {
    U4D_CHECK(cv::imwrite(tmp.string(), image, {cv::IMWRITE_PNG_COMPRESSION, compression}),
              "cannot write image {}", path.string());
  });
}

// GT mesh of one person: positions, faces and per-vertex colour (the
// material's albedo at the vertex), vertex i the same surface point always.
void WriteMeshPly(const fs::path& path, const SceneObject& person) {
  open3d::geometry::TriangleMesh mesh;
  const SurfaceMesh& m = person.mesh;
  std::vector<int> vertex_material(m.vertices.size(), 0);
  for (size_t f = 0; f < m.faces.size(); ++f)
    for (int k = 0; k < 3; ++k) vertex_material[m.faces[f][k]] = m.face_material[f];
  mesh.vertices_.reserve(m.vertices.size());
  mesh.vertex_colors_.reserve(m.vertices.size());
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    mesh.vertices_.push_back(m.vertices[i].cast<double>());
    const Eigen::Vector3f bgr =
        EvaluateMaterial(person.materials.at(vertex_material[i]), m.texcoords[i]);
    mesh.vertex_colors_.push_back(Eigen::Vector3d(bgr.z(), bgr.y(), bgr.x()).cwiseMin(1.0));
  }
  for (const Eigen::Vector3i& f : m.faces) mesh.triangles_.push_back(f);
  WriteAtomically(path, [&](const fs::path& tmp) {
    U4D_CHECK(open3d::io::WriteTriangleMesh(tmp.string(), mesh, /*write_ascii=*/false,
                                            /*compressed=*/false, /*write_vertex_normals=*/false,
                                            /*write_vertex_colors=*/true),
              "cannot write mesh {}", path.string());
  });
}

std::vector<Pose3d> GtPoses(const SceneFrame& frame) {
  std::vector<Pose3d> poses;
  for (size_t p = 0; p < frame.joints.size(); ++p) {
    Pose3d pose;
    pose.person_id = frame.people[p].instance_id;
    for (int j = 0; j < kNumJoints; ++j) pose.joints[j] << frame.joints[p][j], 1.0;
    poses.push_back(pose);
  }
  return poses;
}

InstanceMask GtInstanceMask(const cv::Mat& instance, const SceneFrame& frame) {
  InstanceMask mask;
  mask.ids = instance;
  std::vector<bool> present(65536, false);
  for (int y = 0; y < instance.rows; ++y) {
    const uint16_t* row = instance.ptr<uint16_t>(y);
    for (int x = 0; x < instance.cols; ++x) present[row[x]] = true;
  }
  for (const SceneObject& person : frame.people)
    if (present[person.instance_id])
      mask.instances.push_back({person.instance_id, person.label, 1.0});
  return mask;
}

nlohmann::json VisibilityJson(const RenderedView& view) {
  nlohmann::json people = nlohmann::json::array();
  for (const VisibilityStats& s : view.visibility)
    people.push_back({{"id", s.instance_id},
                      {"visible_pixels", s.visible_pixels},
                      {"amodal_pixels", s.amodal_pixels},
                      {"visible_fraction", s.VisibleFraction()}});
  return {{"people", people}};
}

Capture MakeCaptureManifest(const SynthOptions& o,
                            const std::vector<std::vector<Camera>>& cameras_per_frame) {
  Capture c;
  c.name = o.name.empty() ? o.preset : o.name;
  c.scene = o.environment.indoor ? SceneType::kIndoor : SceneType::kOutdoor;
  c.fps = o.fps;
  c.num_frames = o.num_frames;
  const bool moving = o.rig.IsMoving();
  for (int v = 0; v < o.rig.num_views; ++v) {
    CaptureView view;
    view.name = fmt::format("cam{:02d}", v);
    view.source.path = "images/" + view.name + "/{:06d}.png";
    if (moving) {
      for (int f = 0; f < o.num_frames; ++f) view.cameras.push_back(cameras_per_frame[f][v]);
    } else {
      view.cameras.push_back(cameras_per_frame[0][v]);
    }
    c.views.push_back(view);
  }
  return c;
}

// The empty stage seen by each (static) camera: background/<view>/<k>.png.
// The times lie after the take's, so that the sensor noise differs from any
// frame of it.
void WriteCleanPlates(const fs::path& dir, const std::vector<Camera>& cameras,
                      const std::vector<std::string>& view_names,
                      const std::vector<SceneObject>& statics, const SynthOptions& options) {
  const std::vector<StaticLayer> layers = RenderStaticLayers(cameras, statics, options.render);
  SceneFrame empty;
  empty.statics = statics;
  for (int k = 0; k < options.clean_plate_frames; ++k) {
    empty.time = (options.num_frames + 1000 + k) / options.fps;
    const std::vector<RenderedView> views = RenderViews(cameras, empty, options.render, &layers);
    for (size_t v = 0; v < views.size(); ++v)
      WritePng(dir / layout::CleanPlateDir() / view_names[v] / (layout::FrameName(k) + ".png"),
               views[v].color, options.png_compression);
  }
}

}  // namespace

SynthSummary WriteSyntheticCapture(const SynthOptions& options, const fs::path& dir,
                                   bool progress) {
  options.Check();
  Timer total_timer;
  SynthSummary summary;
  const int num_views = options.rig.num_views;
  summary.num_frames = options.num_frames;
  summary.num_views = num_views;

  const int script_frames =
      std::max(options.num_frames + std::max(0, options.start_frame),
               static_cast<int>(std::ceil(options.script_seconds * options.fps)));
  const PeopleScript script = MakeScript(options, script_frames);
  const std::vector<CapturedPerformer> captured = LoadCaptured(options);
  const int start = WindowStart(options, script);
  const std::vector<SceneObject> statics = MakeEnvironment(options.environment);
  const auto cameras = RigSequence(options.rig, options.num_frames, options.fps);
  summary.num_people = static_cast<int>(script.people.size() + captured.size());
  summary.num_objects = static_cast<int>(options.props.size());

  fs::create_directories(dir);
  // capture.json is written last and marks a complete capture: remove a stale one first.
  fs::remove(dir / "capture.json");
  const Capture capture = MakeCaptureManifest(options, cameras);
  std::vector<std::string> view_names;
  for (const CaptureView& v : capture.views) view_names.push_back(v.name);

  auto pose_frame = [&](int f) {
    SceneFrame frame;
    const int g = options.still_people ? 0 : f;
    PosePeople(script, start + g, &frame);
    for (const CapturedPerformer& c : captured)
      frame.people.push_back(
          PoseCapturedPerformer(c, g, static_cast<int>(frame.people.size()) + 1));
    frame.time = FrameTime(script, start + f);  // still people: the sensor noise still changes
    for (SceneObject& prop :
         PoseProps(options.props, frame, static_cast<int>(frame.people.size()) + 1))
      frame.people.push_back(std::move(prop));
    frame.statics = statics;
    return frame;
  };
  // Without any skeleton (only captured performers) the capture holds no 2D
  // keypoints and no GT joints, rather than files that say nobody was seen.
  const bool keypoints = !script.people.empty();

  nlohmann::json degradation = nlohmann::json::array();
  nlohmann::json contacts = nlohmann::json::array();
  std::mutex mutex;
  Progress bar("synth", options.num_frames, progress);

  // A static rig sees the same background every frame: render it once.
  const bool moving = options.rig.IsMoving();
  Timer render_timer;
  std::vector<StaticLayer> layers;
  if (!moving) layers = RenderStaticLayers(cameras[0], statics, options.render);
  const std::vector<StaticLayer>* layers_ptr = moving ? nullptr : &layers;

  SceneFrame frame = pose_frame(0);
  std::vector<RenderedView> views = RenderViews(cameras[0], frame, options.render, layers_ptr);
  summary.render_seconds += render_timer.Seconds();
  std::vector<DetectorMemory> detector_memory(num_views);

  for (int f = 0; f < options.num_frames; ++f) {
    // Render t+1 first: the forward flow of frame t needs it.
    SceneFrame next;
    std::vector<RenderedView> next_views;
    if (f + 1 < options.num_frames) {
      next = pose_frame(f + 1);
      render_timer.Restart();
      next_views = RenderViews(cameras[f + 1], next, options.render, layers_ptr);
      summary.render_seconds += render_timer.Seconds();
    }

    const FloorShadowMap shadows =
        MakeFloorShadowMap(frame, options.render.light_direction, options.effects);
    const std::vector<std::pair<int, int>> in_contact = PeopleInContact(frame);
    std::map<int, std::string> classes;
    for (const SceneObject& o : frame.people) classes[o.instance_id] = o.label;
    contacts.push_back({{"frame", f}, {"pairs", in_contact}});
    tbb::parallel_for(0, num_views, [&](int v) {
      const std::string& name = view_names[v];
      RenderedView& rv = views[v];
      WriteInstanceMask(dir / layout::GtInstances(name, f), dir / layout::GtInstancesInfo(name, f),
                        GtInstanceMask(rv.instance, frame));
      WritePfm(dir / layout::GtDepth(name, f), rv.depth);
      WriteJsonFileAtomic(dir / layout::GtVisibility(name, f), VisibilityJson(rv));
      cv::Mat forward_flow;
      if (f + 1 < options.num_frames) {
        Timer flow_timer;
        const FlowField flow = ForwardFlow(rv, frame, next, cameras[f][v], cameras[f + 1][v],
                                           next_views[v], options.flow);
        {
          std::lock_guard<std::mutex> lock(mutex);
          summary.render_seconds += flow_timer.Seconds();
        }
        WriteFlo(dir / layout::GtFlow(name, f), flow.flow);
        WritePng(dir / layout::GtFlowValid(name, f), flow.valid, options.png_compression);
        forward_flow = flow.flow;
      }
      ApplyFloorShadows(cameras[f][v], rv.depth, rv.instance, shadows, options.effects, &rv.color);
      ApplySpill(rv.instance, options.effects, &rv.color);
      ApplyMotionBlur(forward_flow, rv.instance, options.effects, &rv.color);
      WritePng(dir / layout::Image(name, f), rv.color, options.png_compression);

      // Initial inputs, as a detector would give them.
      const DegradedMask degraded =
          DegradeInstanceMask(rv.instance, rv.part, options.masks, DegradeSeed(options.seed, v, f),
                              &detector_memory[v], &in_contact, &classes);
      if (!degraded.dropped)
        WriteInstanceMask(dir / layout::Mask(name, f), dir / layout::MaskInfo(name, f),
                          degraded.mask);
      int swapped = 0;
      if (keypoints) {
        const auto detections =
            DegradeKeypoints(frame.coco_keypoints, cameras[f][v], rv.instance, options.keypoints,
                             DegradeSeed(options.seed + 0x9e3779b9ull, v, f));
        std::vector<Pose2d> poses;
        for (const DetectedPose2d& d : detections) {
          Pose2d pose;
          pose.keypoints = d.keypoints;
          pose.score = d.score;
          poses.push_back(pose);
          swapped += d.swapped ? 1 : 0;
        }
        WritePoses2d(dir / layout::Poses2d(name, f), poses);
      }

      std::lock_guard<std::mutex> lock(mutex);
      summary.dropped_masks += degraded.dropped ? 1 : 0;
      summary.merged_instances += static_cast<int>(degraded.merged_gt_ids.size());
      summary.false_positives += degraded.false_positives;
      summary.dropped_limbs += degraded.dropped_limbs;
      summary.swapped_poses += swapped;
      if (degraded.dropped || !degraded.merged_gt_ids.empty() || !degraded.missed_gt_ids.empty())
        degradation.push_back({{"view", name},
                               {"frame", f},
                               {"dropped", degraded.dropped},
                               {"merged_gt_ids", degraded.merged_gt_ids},
                               {"missed_gt_ids", degraded.missed_gt_ids}});
    });

    if (keypoints) WritePoses3d(dir / layout::GtJoints3d(f), GtPoses(frame));
    if (options.write_meshes) {
      for (const SceneObject& person : frame.people)
        WriteMeshPly(dir / layout::GtMesh(person.instance_id, f), person);
    }
    frame = std::move(next);
    views = std::move(next_views);
    bar.Tick();
  }
  bar.Finish();

  std::sort(degradation.begin(), degradation.end(), [](const auto& a, const auto& b) {
    return std::make_pair(a["frame"].template get<int>(), a["view"].template get<std::string>()) <
           std::make_pair(b["frame"].template get<int>(), b["view"].template get<std::string>());
  });
  WriteJsonFileAtomic(
      dir / "gt/degradation.json",
      {{"note", "what the initial masks got wrong, for evaluation only"}, {"events", degradation}});
  WriteJsonFileAtomic(dir / layout::GtContacts(),
                      {{"note", "pairs of GT ids whose surfaces come within distance metres"},
                       {"distance", kContactDistance},
                       {"frames", contacts}});
  if (options.clean_plate_frames > 0)
    WriteCleanPlates(dir, cameras[0], view_names, statics, options);
  // The manifest last: a capture whose capture.json exists is complete.
  WriteCapture(capture, dir);
  summary.seconds = total_timer.Seconds();
  return summary;
}

void UseKeyedStage(SynthOptions* o) {
  o->environment.keyed = true;
  o->effects.spill_strength = 0.3;
  o->effects.shadow_strength = std::max(o->effects.shadow_strength, 0.45);
  // The spill has the colour of the backdrop as the camera sees it (its
  // albedo through the renderer's gamma).
  for (int c = 0; c < 3; ++c)
    o->effects.spill_colour[c] =
        255.0f * std::pow(o->environment.key_colour[c], 1.0f / static_cast<float>(o->render.gamma));
}

SynthOptions SmallHandshakeOptions(int num_views, int width, int height, int num_frames) {
  SynthOptions o = SynthPreset("handshake");
  o.rig.num_views = num_views;
  o.rig.image_width = width;
  o.rig.image_height = height;
  o.num_frames = num_frames;
  o.write_meshes = false;
  return o;
}

SynthOptions SmallRealisticOptions(const fs::path& captured_meshes, int width, int height,
                                   int num_frames) {
  SynthOptions o = SynthPreset("realistic");
  o.captured_meshes = captured_meshes;
  o.rig.image_width = width;
  o.rig.image_height = height;
  o.num_frames = num_frames;
  o.write_meshes = false;
  return o;
}

fs::path WriteCaptureToTempDir(const std::string& name, const SynthOptions& options,
                               SynthSummary* summary) {
  fs::path dir =
      fs::temp_directory_path() / fmt::format("u4d_{}_{}", name, static_cast<long>(::getpid()));
  fs::remove_all(dir);
  const SynthSummary s = WriteSyntheticCapture(options, dir);
  if (summary != nullptr) *summary = s;
  return dir;
}

}  // namespace u4d::synth
