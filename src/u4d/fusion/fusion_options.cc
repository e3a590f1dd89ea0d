#include "u4d/fusion/fusion_options.h"

namespace u4d {

void DeclareOptions(OptionRegistry& r, FusionOptions* o) {
  r.Add("pixel_step", &o->pixel_step, "use every pixel_step-th row and column");
  r.Add("max_depth_jump", &o->max_depth_jump, "metres; larger neighbour differences are edges");
  r.Add("max_view_angle_deg", &o->max_view_angle_deg, "drop points seen more obliquely than this");
  r.Add("consistency_filter", &o->consistency_filter, "drop points no other view confirms");
  r.Add("min_agreeing_views", &o->min_agreeing_views,
        "with the filter: other views that must agree");
  r.Add("consistency_tolerance", &o->consistency_tolerance,
        "metres of depth difference counted as agreement (above the depth maps' own error)");
  r.Add("min_confidence", &o->min_confidence, "drop points with a lower confidence (in [0, 1])");
  r.Add("min_points", &o->min_points, "fewer oriented points: empty result");
  r.Add("poisson_depth", &o->poisson_depth, "octree depth of the Poisson reconstruction");
  r.Add("poisson_scale", &o->poisson_scale, "Poisson bounding-cube scale over the points");
  r.Add("poisson_threads", &o->poisson_threads,
        "Open3D Poisson threads (-1 = all; 1 is deterministic)");
  r.Add("density_quantile", &o->density_quantile, "trim vertices below this density quantile");
  r.Add("trim_distance_factor", &o->trim_distance_factor,
        "trim vertices farther than this x point spacing");
  r.Add("min_component_fraction", &o->min_component_fraction,
        "drop components with fewer triangles (share)");
  r.Add("silhouette_min_views", &o->silhouette.min_views,
        "trim vertices that this many views see outside the object's mask (0 = off)");
  r.Add("silhouette_margin_px", &o->silhouette.margin_px,
        "pixels; a vertex this close to the object's mask counts as inside it");
  r.Add("silhouette_occlusion_tolerance", &o->silhouette.occlusion_tolerance,
        "metres; another object nearer by more hides the vertex from that view");
  r.Add("silhouette_support_factor", &o->silhouette.support_factor,
        "point spacings; a vertex this near a depth point is trimmed only when more views see it "
        "off the mask than on it");
  r.Add("fill_hole_radius", &o->fill_hole_radius,
        "metres; the trimmed surface's holes up to this radius are closed (0 = off)");
  r.Add("depth_from_meshes", &o->depth_from_meshes,
        "the written depth maps take the fused surface's depth on the object's own pixels");
}

void DeclareOptions(OptionRegistry& r, TrackOptions* o) {
  r.Add("visibility_tolerance", &o->visibility_tolerance,
        "metres between vertex depth and the depth map at t, plus 2 depth_sigma_rel of the depth");
  r.Add("max_depth_jump", &o->max_depth_jump, "metres; bilinear depth only across smaller steps");
  r.Add("consistency_tolerance", &o->consistency_tolerance, "metres; candidates this close agree");
  r.Add("refine_iterations", &o->refine_iterations,
        "Gauss-Newton steps on the reprojections (0 = off)");
  r.Add("flow_sigma_px", &o->flow_sigma_px,
        "expected flow error, pixels (joint flow EPE on people 0.25-0.65)");
  r.Add("depth_sigma_rel", &o->depth_sigma_rel,
        "expected depth error, fraction of the depth (about half the joint depths are within 1 %)");
  r.Add("diffusion_iterations", &o->diffusion_iterations,
        "Jacobi iterations for untracked vertices");
}

void DeclareOptions(OptionRegistry& r, FlowConsensusOptions* o) {
  r.Add("enabled", &o->enabled, "each view's flow on objects from the motion all views see");
  r.Add("min_views", &o->min_views, "views that must see a point for its flow to change");
  r.Add("visibility_tolerance", &o->visibility_tolerance,
        "metres between a point's depth and a view's depth map, plus 2 depth_sigma_rel of it");
  r.Add("depth_sigma_rel", &o->depth_sigma_rel, "the depth maps' relative error");
  r.Add("max_depth_jump", &o->max_depth_jump, "metres; bilinear depth only across smaller steps");
  r.Add("robust_scale_px", &o->robust_scale_px,
        "Cauchy scale of a view's flow residual, working pixels");
  r.Add("iterations", &o->iterations, "IRLS steps after the two least-squares steps");
}

void DeclareOptions(OptionRegistry& r, GltfOptions* o) {
  r.Add("fps", &o->fps, "frames per second of the animation");
  r.Add("normals", &o->normals, "write the first frame's vertex normals");
}

}  // namespace u4d
