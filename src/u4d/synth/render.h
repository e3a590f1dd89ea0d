// CPU rasteriser for synthetic captures with exact per-pixel ground truth.
//
// RenderView draws one SceneFrame (synth/scene.h) into one pinhole Camera with
// a z-buffer: triangles are clipped against the near plane z = near_plane in
// the camera frame, projected, and rasterised at pixel centres (pixel (x, y)
// samples the ray through the point (x, y), origin at the centre of the
// top-left pixel, docs/conventions.md) with the top-left fill rule, so two
// triangles sharing an edge never both cover, nor both miss, a pixel on it.
// Attributes are interpolated perspective-correctly. Lens distortion is not
// rasterised: a camera with distortion is rejected (u4d::Error).
//
// Ground truth per pixel, for the nearest surface on the ray through its centre:
//  depth        z of the surface point in the camera frame (metres), 0 where no
//               geometry; exact for the planar triangles up to float rounding.
//  instance     the person's instance_id, 0 for static geometry and nothing.
//  part         BodyPart of the vertex with the largest barycentric weight
//               (kNone for static geometry and nothing).
//  object       surface identity: 0 = nothing, 1 + k = frame.people[k],
//               1 + num_people + j = frame.statics[j] (ObjectRef decodes it).
//  face         index of the triangle in that object's mesh, -1 where nothing.
//  barycentric  (b1, b2) of the surface point in that triangle, b0 = 1 - b1 - b2:
//               point = b0 V[f0] + b1 V[f1] + b2 V[f2]. With vertex identity
//               stable over time (scene.h) this names the same material point
//               at every frame, which is what ForwardFlow uses.
//
// Colour (linear material colour -> 8-bit BGR): albedo = EvaluateMaterial at the
// interpolated texcoord, band-limited by the pixel footprint; shading is
// Lambertian, two-sided, with smooth (area-weighted vertex) normals:
//   c = gain * albedo * (ambient + light_intensity * max(0, n . -light_direction)),
// then gamma-encoded (c^(1/gamma)), scaled to [0, 255], plus Gaussian noise of
// noise_sigma grey levels, rounded and saturated. Empty pixels are black.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"
#include "u4d/synth/scene.h"

namespace u4d::synth {

struct RenderOptions {
  Eigen::Vector3d light_direction{-0.4, -1.0, -0.3};  // direction light travels (world)
  float light_intensity = 0.75f;                      // directional light strength
  float ambient = 0.35f;                              // ambient light strength
  float gain = 1.0f;               // camera gain (exposure multiplier) for every view
  float gain_jitter = 0.0f;        // RenderViews: view v's gain *= 1 + gain_jitter * U(-1, 1)
  float gamma = 2.2f;              // display gamma used to encode the 8-bit colour
  float noise_sigma = 1.5f;        // Gaussian sensor noise, 8-bit grey levels; 0 = none
  uint32_t noise_seed = 0;         // seeds sensor noise and gain jitter
  double near_plane = 0.05;        // clip distance in front of the camera (m)
  bool cull_back_faces = false;    // skip triangles seen from behind (closed meshes only)
  bool texture_filtering = true;   // band-limit textures by the pixel footprint
  bool compute_visibility = true;  // fill RenderedView::visibility (amodal silhouettes)

  void Check() const;  // throws u4d::Error on non-finite or out-of-range values
};

// Per view, per person: how much of the person is seen.
struct VisibilityStats {
  int instance_id = 0;
  int64_t visible_pixels = 0;  // pixels whose nearest surface is this person
  int64_t amodal_pixels = 0;   // pixels the person covers when rendered alone
  double VisibleFraction() const {
    return amodal_pixels > 0 ? static_cast<double>(visible_pixels) / amodal_pixels : 0.0;
  }
};

struct RenderedView {
  cv::Mat color;                            // CV_8UC3, BGR
  cv::Mat depth;                            // CV_32FC1, z in the camera frame (m), 0 = no geometry
  cv::Mat instance;                         // CV_16UC1, person instance id, 0 = static / nothing
  cv::Mat part;                             // CV_8UC1, BodyPart
  cv::Mat object;                           // CV_16UC1, surface identity (see above), 0 = nothing
  cv::Mat face;                             // CV_32SC1, triangle index, -1 = nothing
  cv::Mat barycentric;                      // CV_32FC2, (b1, b2)
  std::vector<VisibilityStats> visibility;  // one per person, frame.people order
};

// Decoded `object` value: which SceneObject of the frame a pixel shows.
struct ObjectRef {
  bool is_person = false;
  int index = -1;  // into frame.people or frame.statics; -1 for "nothing"
};
ObjectRef DecodeObject(const SceneFrame& frame, int object_value);
// Throws when the value names no object of the frame; nullptr for 0.
const SceneObject* FindObject(const SceneFrame& frame, int object_value);

// Throws u4d::Error when the frame breaks scene.h's contract in a way the
// renderer would trip on (index out of range, size mismatch, missing material,
// non-finite vertex, more than 65534 objects).
void CheckSceneFrame(const SceneFrame& frame);

// The static objects of a scene rendered once for one camera: their id
// buffers and their linear shaded colour (before gain, gamma and noise). A
// static camera sees the same statics every frame, so RenderView can start
// from the layer and rasterise and shade only the people: the result is
// identical to a full render (tested), at a fraction of the cost when the
// background's textures dominate.
struct StaticLayer {
  Camera camera;           // the camera it was rendered for
  size_t num_statics = 0;  // frame.statics.size() it was rendered from
  cv::Mat depth;           // CV_32FC1, z (m), +inf where nothing
  cv::Mat object;          // CV_16UC1, 1 + index into statics, 0 = nothing
  cv::Mat face;            // CV_32SC1
  cv::Mat barycentric;     // CV_32FC2
  cv::Mat shade;           // CV_32FC3, linear BGR albedo * light
};

StaticLayer RenderStaticLayer(const Camera& camera, const std::vector<SceneObject>& statics,
                              const RenderOptions& options = {});
std::vector<StaticLayer> RenderStaticLayers(const std::vector<Camera>& cameras,
                                            const std::vector<SceneObject>& statics,
                                            const RenderOptions& options = {});

// Renders one view. `view_index` and frame.time select the sensor-noise stream
// (deterministic: the same inputs give the same image) and the gain jitter.
// With `layer` (rendered for this very camera from frame.statics) only the
// people are rasterised; throws when the layer's camera or static count differ.
RenderedView RenderView(const Camera& camera, const SceneFrame& frame,
                        const RenderOptions& options = {}, int view_index = 0,
                        const StaticLayer* layer = nullptr);

// Renders all views in parallel (TBB); view v uses view_index v and, when
// given, (*layers)[v].
std::vector<RenderedView> RenderViews(const std::vector<Camera>& cameras, const SceneFrame& frame,
                                      const RenderOptions& options = {},
                                      const std::vector<StaticLayer>* layers = nullptr);

struct FlowOptions {
  double depth_tolerance = 0.01;            // absolute part of the visibility tolerance (m)
  double relative_depth_tolerance = 0.005;  // plus this fraction of the depth

  void Check() const;
};

struct FlowField {
  // Forward flow (u, v) in pixels: p + flow(p) is where the surface point seen
  // at pixel p at t is seen at t+1. Filled wherever the point is in front of
  // camera_t1 (also when occluded or out of the image); 0 elsewhere.
  cv::Mat flow;   // CV_32FC2
  cv::Mat valid;  // CV_8UC1, 255 where the flow is valid, 0 elsewhere
};

// Ground-truth forward optical flow from frame t to t+1 for one camera.
// For each pixel of view_t showing a surface (object, face, barycentric), the
// same material point X_t (at frame_t) and X_t1 (at frame_t1, same vertex
// indices) is projected: flow = camera_t1.Project(X_t1) - camera_t.Project(X_t)
// (so static geometry under a static camera has exactly zero flow;
// camera_t.Project(X_t) is the pixel centre up to float rounding, ~1e-5 px).
// Valid (occlusion-aware) where p1 = camera_t1.Project(X_t1) lies in the image
// and the point is visible at t+1: the triangle visible at the pixel nearest to
// p1 in view_t1 (same triangle: visible), extended as a plane, has depth d
// along the ray through p1 with z1 <= d + depth_tolerance +
// relative_depth_tolerance * z1, z1 = camera_t1.Depth(X_t1) (a point more than
// the tolerance behind the visible surface is occluded). The plane extension makes
// the test exact on slanted surfaces. view_t and view_t1 must be renders of
// frame_t with camera_t and frame_t1 with camera_t1; the frames must have the
// same objects with the same face/vertex counts (throws otherwise).
FlowField ForwardFlow(const RenderedView& view_t, const SceneFrame& frame_t,
                      const SceneFrame& frame_t1, const Camera& camera_t, const Camera& camera_t1,
                      const RenderedView& view_t1, const FlowOptions& options = {});

}  // namespace u4d::synth
