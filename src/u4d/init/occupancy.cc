// People separated on a ground-plane occupancy map (init.h, step 6).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <numeric>
#include <optional>
#include <tuple>

#include <tbb/parallel_for.h>
#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include "u4d/init/init.h"
#include "u4d/init/init_internal.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

// Union-find over region indices (the saddle merge of the columns' regions).
int Find(std::vector<int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

// The point nearest (least squares) to all optical axes.
Eigen::Vector3d AxesCentre(const std::vector<Camera>& cameras) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Camera& c : cameras) {
    const Eigen::Vector3d d = c.ViewDirection().normalized();
    const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - d * d.transpose();
    a += p;
    b += p * c.Center();
  }
  // Parallel axes leave `a` singular: fall back to the mean centre.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(a);
  if (eig.eigenvalues()(0) < 1e-6 * std::max(1.0, eig.eigenvalues()(2))) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Camera& c : cameras) mean += c.Center();
    return mean / static_cast<double>(cameras.size());
  }
  return a.ldlt().solve(b);
}

// Pixels of `fg` (0/255) without an id take the id of the nearest pixel that
// has one when it is at most `radius` px away; the others stay background.
cv::Mat FillFromNearestId(const cv::Mat& ids, const cv::Mat& fg, double radius) {
  cv::Mat out = cv::Mat::zeros(ids.size(), CV_16UC1);
  ids.copyTo(out, fg);
  cv::Mat unlabelled = out == 0;
  if (cv::countNonZero(unlabelled) == static_cast<int>(out.total())) return out;
  cv::Mat distance, nearest;  // nearest: 1-based index of the nearest labelled pixel
  cv::distanceTransform(unlabelled, distance, nearest, cv::DIST_L2, 3, cv::DIST_LABEL_PIXEL);
  std::vector<uint16_t> id_of(out.total() + 1, 0);
  for (int y = 0; y < out.rows; ++y)
    for (int x = 0; x < out.cols; ++x)
      if (const uint16_t id = out.at<uint16_t>(y, x)) id_of[nearest.at<int>(y, x)] = id;
  for (int y = 0; y < out.rows; ++y)
    for (int x = 0; x < out.cols; ++x)
      if (fg.at<uint8_t>(y, x) && !out.at<uint16_t>(y, x) && distance.at<float>(y, x) <= radius)
        out.at<uint16_t>(y, x) = id_of[nearest.at<int>(y, x)];
  return out;
}

// The grid of SeparatePeopleOnGround (init.h): up, ground axes, origin and
// cell size; height and people are left empty.
OccupancyMap MakeGrid(const std::vector<Camera>& cameras, const InitOptions& options) {
  // The grid: a cube centred on the point nearest the optical axes, with
  // axes (a, b) on the ground plane and `up`.
  const int nv = static_cast<int>(cameras.size());
  OccupancyMap m;
  m.up = RigUpDirection(cameras);
  const Eigen::Vector3d centre = AxesCentre(cameras);
  std::vector<double> distances;
  distances.reserve(cameras.size());
  for (const Camera& c : cameras) distances.push_back((c.Center() - centre).norm());
  std::nth_element(distances.begin(), distances.begin() + nv / 2, distances.end());
  const double half = options.ground.occupancy_extent * distances[nv / 2];
  U4D_CHECK(half > 0, "SeparatePeopleOnGround: all cameras sit at the rig centre");
  m.axis_a = m.up.unitOrthogonal();
  m.axis_b = m.up.cross(m.axis_a);
  m.cells = options.ground.occupancy_cells;
  m.cell_m = 2 * half / m.cells;
  m.origin = centre - half * (m.axis_a + m.axis_b + m.up);
  return m;
}

size_t Voxel(int n, int i, int j, int k) { return (static_cast<size_t>(k) * n + j) * n + i; }

std::vector<uint8_t> OccupiedVoxels(const OccupancyMap& m, const ReducedMasks& reduced,
                                    const InitOptions& options) {
  // Occupied voxels: in the foreground of at least min_view_fraction of the
  // views whose image they fall in, seen by at least min(occupancy_min_views, nv).
  const int n = m.cells, nv = static_cast<int>(reduced.cameras.size());
  const std::vector<Camera>& small = reduced.cameras;
  const int min_seeing = std::min(options.ground.occupancy_min_views, nv);
  std::vector<uint8_t> occupied(static_cast<size_t>(n) * n * n, 0);
  const auto centre_of = [&](double i, double j, double k) -> Eigen::Vector3d {
    return m.origin + m.cell_m * (i * m.axis_a + j * m.axis_b + k * m.up);
  };
  tbb::parallel_for(0, n, [&](int j) {
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector3d x = centre_of(i + 0.5, j + 0.5, k + 0.5);
        int inside = 0, fg = 0;
        for (int v = 0; v < nv; ++v) {
          const std::optional<Eigen::Vector2i> p = NearestPixel(small[v], x);
          if (!p) continue;
          ++inside;
          if (reduced.target[v].at<uint8_t>(p->y(), p->x())) {
            ++fg;
          } else if (inside - fg > (1 - options.cross_view.min_view_fraction) * nv + 1e-9) {
            break;  // too many misses already: at most nv views can see it
          }
        }
        occupied[Voxel(n, i, j, k)] =
            inside >= min_seeing &&
            fg >= std::ceil(options.cross_view.min_view_fraction * inside - 1e-9);
      }
  });
  return occupied;
}

// Fills m->height; returns the candidate person (1..*candidates) of every
// ground column, 0 for none (CV_16UC1, row = axis_b index).
cv::Mat CandidatePeople(const std::vector<uint8_t>& occupied, const InitOptions& options,
                        OccupancyMap* m, int* candidates) {
  // Column heights (occupied voxels per column), smoothed.
  const int n = m->cells;
  m->height = cv::Mat::zeros(n, n, CV_32FC1);  // row = b index, column = a index
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int count = 0;
      for (int k = 0; k < n; ++k) count += occupied[Voxel(n, i, j, k)];
      m->height.at<float>(j, i) = static_cast<float>(count * m->cell_m);
    }
  cv::Mat smooth;
  const double sigma = std::max(0.5, options.ground.person_smoothing_m / m->cell_m);
  cv::GaussianBlur(m->height, smooth, cv::Size(0, 0), sigma);

  // Regions: every column at least min_column_height_m high climbs the
  // smoothed height to a local maximum; regions whose saddle is at least
  // person_saddle_ratio of the lower peak merge (one person's legs and
  // arms), lower saddles separate people.
  std::vector<int> region(static_cast<size_t>(n) * n, -1);
  std::vector<int> peak_cell;
  const auto candidate = [&](int i, int j) {
    return i >= 0 && j >= 0 && i < n && j < n &&
           m->height.at<float>(j, i) >= options.ground.min_column_height_m;
  };
  const auto S = [&](int c) { return smooth.at<float>(c / n, c % n); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (!candidate(i, j) || region[j * n + i] >= 0) continue;
      std::vector<int> path;
      int c = j * n + i;
      while (region[c] < 0) {
        path.push_back(c);
        int best = c;
        for (int dj = -1; dj <= 1; ++dj)
          for (int di = -1; di <= 1; ++di) {
            const int ci = c % n + di, cj = c / n + dj;
            if (candidate(ci, cj) && S(cj * n + ci) > S(best)) best = cj * n + ci;
          }
        if (best == c) {
          region[c] = static_cast<int>(peak_cell.size());
          peak_cell.push_back(c);
          break;
        }
        c = best;
      }
      for (const int p : path) region[p] = region[c];
    }
  const int nr = static_cast<int>(peak_cell.size());
  struct Saddle {
    float height;
    int a, b;
  };
  std::vector<Saddle> saddles;
  for (int c = 0; c < n * n; ++c) {
    if (region[c] < 0) continue;
    for (const int d : {1, n, n + 1, n - 1}) {
      const int o = c + d;
      if (o >= n * n || (d != n && std::abs(o % n - c % n) != 1) || region[o] < 0 ||
          region[o] == region[c])
        continue;
      saddles.push_back({std::min(S(c), S(o)), region[c], region[o]});
    }
  }
  std::sort(saddles.begin(), saddles.end(),
            [](const Saddle& x, const Saddle& y) { return x.height > y.height; });
  std::vector<int> parent(nr);
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<float> peak(nr);
  for (int r = 0; r < nr; ++r) peak[r] = S(peak_cell[r]);
  for (const Saddle& s : saddles) {
    const int a = Find(parent, s.a), b = Find(parent, s.b);
    if (a == b || s.height < options.ground.person_saddle_ratio * std::min(peak[a], peak[b]))
      continue;
    if (peak[a] < peak[b]) {
      parent[a] = b;
    } else {
      parent[b] = a;
    }
  }
  // People: merged regions whose highest column reaches min_person_height_m.
  // A lower region (a leg or an arm whose saddle is low, or a person
  // crouching or lunging with parts missing from some masks) joins the
  // tallest such region it touches, else is a person of its own when it
  // reaches min_lone_height_m. Ids ordered along axis_a, then axis_b, of the peak.
  const auto tops = [&] {
    std::vector<float> top(nr, 0);
    for (int c = 0; c < n * n; ++c)
      if (region[c] >= 0) {
        float& t = top[Find(parent, region[c])];
        t = std::max(t, m->height.at<float>(c / n, c % n));
      }
    return top;
  };
  std::vector<float> top = tops();
  std::vector<int> join(nr, -1);  // low root -> the tall root it joins
  for (const Saddle& s : saddles) {
    const int a = Find(parent, s.a), b = Find(parent, s.b);
    if (a == b) continue;
    for (const auto& [low, tall] : {std::pair{a, b}, std::pair{b, a}})
      if (top[low] < options.ground.min_person_height_m &&
          top[tall] >= options.ground.min_person_height_m &&
          (join[low] < 0 || top[tall] > top[join[low]]))
        join[low] = tall;
  }
  for (int r = 0; r < nr; ++r)
    if (join[r] >= 0) parent[r] = join[r];
  top = tops();
  std::vector<int> roots;
  for (int r = 0; r < nr; ++r)
    if (Find(parent, r) == r && top[r] >= options.ground.min_lone_height_m) roots.push_back(r);
  std::sort(roots.begin(), roots.end(), [&](int x, int y) {
    return std::pair(peak_cell[x] % n, peak_cell[x] / n) <
           std::pair(peak_cell[y] % n, peak_cell[y] / n);
  });
  std::vector<int> id_of_root(nr, 0);
  for (size_t k = 0; k < roots.size(); ++k) id_of_root[roots[k]] = static_cast<int>(k) + 1;
  *candidates = static_cast<int>(roots.size());
  cv::Mat person = cv::Mat::zeros(n, n, CV_16UC1);  // candidate id per column
  for (int c = 0; c < n * n; ++c)
    if (region[c] >= 0) person.at<uint16_t>(c / n, c % n) = id_of_root[Find(parent, region[c])];
  return person;
}

// The ground cell (fractional a, b indices) under world point x.
Eigen::Vector2d GroundCell(const OccupancyMap& m, const Eigen::Vector3d& x) {
  const Eigen::Vector3d d = x - m.origin;
  return {d.dot(m.axis_a) / m.cell_m, d.dot(m.axis_b) / m.cell_m};
}

// The candidate at or nearest (within `radius` cells) the column under
// `cell`; 0 for none.
int CandidateNear(const cv::Mat& person, const Eigen::Vector2d& cell, int radius) {
  const int n = person.rows, ci = static_cast<int>(std::floor(cell.x())),
            cj = static_cast<int>(std::floor(cell.y()));
  int best = 0, best_d = radius * radius + 1;
  for (int j = std::max(0, cj - radius); j <= std::min(n - 1, cj + radius); ++j)
    for (int i = std::max(0, ci - radius); i <= std::min(n - 1, ci + radius); ++i) {
      const int id = person.at<uint16_t>(j, i), d = (i - ci) * (i - ci) + (j - cj) * (j - cj);
      if (id && d < best_d) best = id, best_d = d;
    }
  return best;
}

// Candidates holding (within previous_radius_m) the ground positions of two
// or more of the previous frame's people are split between them, each column
// to the nearest of those positions: people who touch merge on the map, but
// not in time. Returns the new number of candidates.
int SplitByPrevious(const std::vector<Eigen::Vector3d>& previous, const OccupancyMap& m,
                    const InitOptions& options, cv::Mat* person, int candidates) {
  const int radius = static_cast<int>(std::ceil(options.ground.previous_radius_m / m.cell_m));
  std::vector<std::vector<Eigen::Vector2d>> held(candidates + 1);
  for (const Eigen::Vector3d& p : previous) {
    const Eigen::Vector2d cell = GroundCell(m, p);
    if (const int id = CandidateNear(*person, cell, radius)) held[id].push_back(cell);
  }
  std::vector<std::vector<int>> parts(candidates + 1);
  int next = candidates;
  for (int id = 1; id <= candidates; ++id)
    if (held[id].size() >= 2) {
      parts[id].push_back(id);
      for (size_t k = 1; k < held[id].size(); ++k) parts[id].push_back(++next);
    }
  for (int j = 0; j < person->rows; ++j)
    for (int i = 0; i < person->cols; ++i) {
      uint16_t& id = person->at<uint16_t>(j, i);
      if (parts[id].empty()) continue;
      const Eigen::Vector2d c(i + 0.5, j + 0.5);
      size_t nearest = 0;
      for (size_t k = 1; k < held[id].size(); ++k)
        if ((held[id][k] - c).squaredNorm() < (held[id][nearest] - c).squaredNorm()) nearest = k;
      id = static_cast<uint16_t>(parts[id][nearest]);
    }
  return next;
}

// Per person (index 0 unused), the height-weighted mean of its columns'
// ground positions (world, on the grid's floor).
std::vector<Eigen::Vector3d> PeoplePositions(const OccupancyMap& m) {
  std::vector<Eigen::Vector3d> sum(m.num_people + 1, Eigen::Vector3d::Zero());
  std::vector<double> weight(m.num_people + 1, 0.0);
  for (int j = 0; j < m.cells; ++j)
    for (int i = 0; i < m.cells; ++i)
      if (const int id = m.people.at<uint16_t>(j, i)) {
        const double h = m.height.at<float>(j, i);
        sum[id] += h * (m.origin + m.cell_m * ((i + 0.5) * m.axis_a + (j + 0.5) * m.axis_b));
        weight[id] += h;
      }
  for (int id = 1; id <= m.num_people; ++id)
    if (weight[id] > 0) sum[id] /= weight[id];
  return sum;
}

// A reduced-resolution foreground pixel's ray: the candidates whose occupied
// voxels it crosses, nearest first.
struct Ray {
  int x, y;
  std::vector<uint16_t> hits;
};

std::vector<std::vector<Ray>> CastRays(const OccupancyMap& m, const cv::Mat& person,
                                       const std::vector<uint8_t>& occupied,
                                       const ReducedMasks& reduced) {
  const int n = m.cells, nv = static_cast<int>(reduced.cameras.size());
  std::vector<std::vector<Ray>> rays(nv);
  tbb::parallel_for(0, nv, [&](int v) {
    const Camera& cam = reduced.cameras[v];
    const Eigen::Matrix3d world_from_cam = cam.cam_from_world.rotation.transpose();
    // Camera centre and ray directions in grid units (cell index coordinates).
    const auto to_grid = [&](const Eigen::Vector3d& w) -> Eigen::Vector3d {
      return Eigen::Vector3d(w.dot(m.axis_a), w.dot(m.axis_b), w.dot(m.up)) / m.cell_m;
    };
    const Eigen::Vector3d o = to_grid(cam.Center() - m.origin);
    for (int y = 0; y < reduced.source[v].rows; ++y)
      for (int x = 0; x < reduced.source[v].cols; ++x) {
        if (!reduced.source[v].at<uint8_t>(y, x)) continue;
        Ray ray{x, y, {}};
        const Eigen::Vector2d nn = cam.PixelToNormalized(Eigen::Vector2d(x, y));
        const Eigen::Vector3d d = to_grid(world_from_cam * Eigen::Vector3d(nn.x(), nn.y(), 1));
        // Slab intersection with the cube [0, n]^3 (t in units of d).
        double t0 = 0, t1 = 1e30;
        for (int a = 0; a < 3; ++a) {
          if (std::abs(d[a]) < 1e-12) {
            if (o[a] < 0 || o[a] > n) t1 = -1;
            continue;
          }
          double ta = (0 - o[a]) / d[a], tb = (n - o[a]) / d[a];
          if (ta > tb) std::swap(ta, tb);
          t0 = std::max(t0, ta);
          t1 = std::min(t1, tb);
        }
        const double step = 0.5 / d.norm();  // half a cell per step
        for (double t = t0; t <= t1; t += step) {
          const Eigen::Vector3d g = o + t * d;
          const int i = std::clamp(static_cast<int>(g.x()), 0, n - 1);
          const int j = std::clamp(static_cast<int>(g.y()), 0, n - 1);
          const int k = std::clamp(static_cast<int>(g.z()), 0, n - 1);
          if (!occupied[Voxel(n, i, j, k)]) continue;
          const uint16_t id = person.at<uint16_t>(j, i);
          if (id && std::find(ray.hits.begin(), ray.hits.end(), id) == ray.hits.end())
            ray.hits.push_back(id);
        }
        if (!ray.hits.empty()) rays[v].push_back(std::move(ray));
      }
  });
  return rays;
}

// Drops phantoms (below); returns the final person id of every candidate (0
// = dropped) and fills m->people, num_people and exclusive_share.
std::vector<uint16_t> RemovePhantoms(const std::vector<std::vector<Ray>>& rays,
                                     const cv::Mat& person, int candidates,
                                     const InitOptions& options, OccupancyMap* m) {
  // Phantoms: where silhouette cones of different people cross, the hull
  // holds volumes no one occupies. Every pixel of a phantom lies in a real
  // person's silhouette, so every ray through it also crosses that person;
  // a real person is the only one on most of its rays in some view. The
  // candidate whose best view has the smallest share of rays crossing it
  // alone goes while that share is below min_exclusive_share (removing one
  // can make another exclusive).
  const int n = m->cells;
  std::vector<uint8_t> alive(candidates + 1, 1);
  alive[0] = 0;
  m->exclusive_share.assign(candidates + 1, 0.0);
  for (int removed = 0; removed < candidates; ++removed) {
    std::vector<double> best(candidates + 1, 0.0);
    for (const std::vector<Ray>& view_rays : rays) {
      std::vector<int> crossing(candidates + 1, 0), alone(candidates + 1, 0);
      for (const Ray& r : view_rays) {
        int count = 0, only = 0;
        for (const uint16_t id : r.hits)
          if (alive[id]) ++crossing[id], ++count, only = id;
        if (count == 1) ++alone[only];
      }
      for (int id = 1; id <= candidates; ++id)
        if (crossing[id] > 0)
          best[id] = std::max(best[id], static_cast<double>(alone[id]) / crossing[id]);
    }
    int worst = 0;
    for (int id = 1; id <= candidates; ++id)
      if (alive[id] && (worst == 0 || best[id] < best[worst])) worst = id;
    for (int id = 1; id <= candidates; ++id)
      if (alive[id]) m->exclusive_share[id] = best[id];
    if (worst == 0 || best[worst] >= options.ground.min_exclusive_share) break;
    alive[worst] = 0;
  }
  // Ids of the people left, in the candidates' order.
  std::vector<uint16_t> final_id(candidates + 1, 0);
  std::vector<double> share(1, 0.0);
  for (int id = 1; id <= candidates; ++id)
    if (alive[id]) {
      final_id[id] = static_cast<uint16_t>(++m->num_people);
      share.push_back(m->exclusive_share[id]);
    }
  m->exclusive_share = share;
  m->people = cv::Mat::zeros(n, n, CV_16UC1);
  for (int c = 0; c < n * n; ++c)
    m->people.at<uint16_t>(c / n, c % n) = final_id[person.at<uint16_t>(c / n, c % n)];
  return final_id;
}

// The instance (step 4's id, 0 = none) under a reduced-resolution pixel.
int InstanceAt(const cv::Mat& inst, cv::Size reduced_size, int x, int y) {
  const double sx = static_cast<double>(inst.cols) / reduced_size.width;
  const double sy = static_cast<double>(inst.rows) / reduced_size.height;
  return inst.at<uint16_t>(std::min(inst.rows - 1, static_cast<int>((y + 0.5) * sy)),
                           std::min(inst.cols - 1, static_cast<int>((x + 0.5) * sx)));
}

// The first candidate a ray meets that is not a phantom, 0 for none.
int NearestCandidate(const std::vector<uint16_t>& hits, const std::vector<uint16_t>& final_id) {
  for (const uint16_t id : hits)
    if (final_id[id]) return id;
  return 0;
}

// The final id of the nearest person a ray crosses, 0 for none.
int NearestPerson(const std::vector<uint16_t>& hits, const std::vector<uint16_t>& final_id) {
  return final_id[NearestCandidate(hits, final_id)];
}

// Per candidate (index 0 unused), how many instances of one view hold it:
// those whose rays meet it first more often than any other candidate, on at
// least min_split_share x as many rays as the instance that meets it most.
std::vector<int> InstancesHolding(const cv::Mat& inst, const std::vector<Ray>& rays,
                                  cv::Size reduced_size, const std::vector<uint16_t>& final_id,
                                  const InitOptions& options) {
  const int nc = static_cast<int>(final_id.size());
  std::map<int, std::vector<int>> first;  // instance -> rays per candidate
  for (const Ray& r : rays)
    if (const int i = InstanceAt(inst, reduced_size, r.x, r.y)) {
      std::vector<int>& count = first.try_emplace(i, nc, 0).first->second;
      ++count[NearestCandidate(r.hits, final_id)];
    }
  std::vector<int> most(nc, 0), held(nc, 0);
  std::vector<int> own;  // per instance (in map order), the candidate it holds
  for (const auto& [i, count] : first) {
    const int c =
        static_cast<int>(std::max_element(count.begin() + 1, count.end()) - count.begin());
    own.push_back(count[c] > 0 ? c : 0);
    most[c] = std::max(most[c], count[c]);
  }
  size_t k = 0;
  for (const auto& [i, count] : first) {
    const int c = own[k++];
    if (c && count[c] >= options.ground.min_split_share * most[c]) ++held[c];
  }
  return held;
}

// Splits candidate `c`'s columns into `k` people: seeds at its highest column
// and then, in turn, the column farthest from the seeds among those at least
// half as high; then Lloyd's iterations weighted by column height. Returns
// the parts' candidate ids (c first; only c when it has fewer than k columns).
std::vector<int> SplitCandidate(const cv::Mat& height, int c, int k, cv::Mat* person,
                                int* candidates) {
  struct Column {
    int i, j;
    double h;
  };
  std::vector<Column> columns;
  double top = 0;
  for (int j = 0; j < person->rows; ++j)
    for (int i = 0; i < person->cols; ++i)
      if (person->at<uint16_t>(j, i) == c) {
        columns.push_back({i, j, height.at<float>(j, i)});
        top = std::max(top, columns.back().h);
      }
  if (static_cast<int>(columns.size()) < k) return {c};
  const auto d2 = [](const Column& a, const Eigen::Vector2d& b) {
    return (Eigen::Vector2d(a.i, a.j) - b).squaredNorm();
  };
  std::vector<Eigen::Vector2d> centre;
  const auto highest = std::max_element(columns.begin(), columns.end(),
                                        [](const Column& a, const Column& b) { return a.h < b.h; });
  centre.emplace_back(highest->i, highest->j);
  while (static_cast<int>(centre.size()) < k) {
    double best = -1;
    Eigen::Vector2d far;
    for (const Column& col : columns) {
      if (col.h < 0.5 * top) continue;
      double nearest = 1e30;
      for (const Eigen::Vector2d& x : centre) nearest = std::min(nearest, d2(col, x));
      if (nearest > best) best = nearest, far = Eigen::Vector2d(col.i, col.j);
    }
    centre.push_back(far);
  }
  std::vector<int> part(columns.size(), 0);
  for (int iteration = 0; iteration < 20; ++iteration) {
    for (size_t n = 0; n < columns.size(); ++n)
      for (int p = 1; p < k; ++p)
        if (d2(columns[n], centre[p]) < d2(columns[n], centre[part[n]])) part[n] = p;
    std::vector<Eigen::Vector2d> sum(k, Eigen::Vector2d::Zero());
    std::vector<double> weight(k, 0.0);
    for (size_t n = 0; n < columns.size(); ++n) {
      sum[part[n]] += columns[n].h * Eigen::Vector2d(columns[n].i, columns[n].j);
      weight[part[n]] += columns[n].h;
    }
    for (int p = 0; p < k; ++p)
      if (weight[p] > 0) centre[p] = sum[p] / weight[p];
  }
  std::vector<int> id_of(k, c);
  for (int p = 1; p < k; ++p) id_of[p] = ++*candidates;
  for (size_t n = 0; n < columns.size(); ++n)
    person->at<uint16_t>(columns[n].j, columns[n].i) = static_cast<uint16_t>(id_of[part[n]]);
  return id_of;
}

// People who touch are one candidate on the map, separate instances in the
// views that see them apart (init.h): a candidate that k >= 2 instances
// hold in at least instance_split_view_share of the views where any holds
// it (and in two views at least) is split into k. Returns the parts of each
// split candidate (SplitCandidate).
std::vector<std::vector<int>> SplitByInstances(const std::vector<cv::Mat>& instances,
                                               const std::vector<std::vector<Ray>>& rays,
                                               const ReducedMasks& reduced,
                                               const std::vector<uint16_t>& final_id,
                                               const InitOptions& options, const OccupancyMap& m,
                                               cv::Mat* person, int* candidates) {
  if (options.ground.instance_split_view_share <= 0) return {};
  const int nc = static_cast<int>(final_id.size());
  std::vector<std::vector<int>> held_in_views(nc);  // candidate -> instances per view holding it
  for (size_t v = 0; v < instances.size(); ++v) {
    const std::vector<int> held =
        InstancesHolding(instances[v], rays[v], reduced.source[v].size(), final_id, options);
    for (int c = 1; c < nc; ++c)
      if (held[c] >= 1) held_in_views[c].push_back(held[c]);
  }
  std::vector<std::vector<int>> split;
  for (int c = 1; c < nc; ++c) {
    std::vector<int>& held = held_in_views[c];
    const int min_views = std::max(
        2,
        static_cast<int>(std::ceil(options.ground.instance_split_view_share * held.size() - 1e-9)));
    if (static_cast<int>(held.size()) < min_views) continue;
    // The largest k that at least min_views views hold.
    std::sort(held.rbegin(), held.rend());
    const int k = held[min_views - 1];
    if (k < 2) continue;
    std::vector<int> parts = SplitCandidate(m.height, c, k, person, candidates);
    if (parts.size() > 1) split.push_back(std::move(parts));
  }
  return split;
}

// Undoes the splits (SplitByInstances' parts) of which a part is not alone on
// min_split_exclusive_share of its rays in any view (RemovePhantoms' share; a
// dropped part has none): the parts' columns return to the first part.
// Returns whether any split was undone.
bool UndoOverlappingSplits(const std::vector<std::vector<int>>& splits,
                           const std::vector<uint16_t>& final_id, const OccupancyMap& m,
                           const InitOptions& options, cv::Mat* person) {
  bool undone = false;
  for (const std::vector<int>& parts : splits) {
    bool apart = true;
    for (const int p : parts)
      apart = apart && final_id[p] != 0 &&
              m.exclusive_share[final_id[p]] >= options.ground.min_split_exclusive_share;
    if (apart) continue;
    for (int y = 0; y < person->rows; ++y)
      for (int x = 0; x < person->cols; ++x) {
        uint16_t& id = person->at<uint16_t>(y, x);
        if (std::find(parts.begin() + 1, parts.end(), id) != parts.end()) id = parts[0];
      }
    undone = true;
  }
  return undone;
}

// Per view, the step-4 instances are the units (they separate people side
// by side in the image, where a few views leave the hull fat); the hull
// names them and splits those that merge people:
//  1. instances and people are paired one to one, largest count first: by
//     rays whose nearest person is that person, then, for people still
//     unpaired, by rays crossing them at all (a person behind another's fat
//     hull is crossed, not first);
//  2. a paired instance in which another person is the nearest on at least
//     min_split_share x as many rays as its own person, and on more rays
//     than in the instance that person holds most so far (its pair, or one
//     split before), is a merge: its pixels take their nearest person among
//     those;
//  3. other instances (fragments) take the person nearest on most of their
//     rays; instances no ray of which crosses a person are dropped, and so
//     are pixels farther than occupancy_fill_fraction x height from any
//     ray that crosses one.
cv::Mat NameInstances(const cv::Mat& inst, const std::vector<Ray>& rays, cv::Size reduced_size,
                      const std::vector<uint16_t>& final_id, int num_people,
                      const InitOptions& options) {
  double max_id = 0;
  cv::minMaxLoc(inst, nullptr, &max_id);
  const int ni = static_cast<int>(max_id) + 1, np = num_people + 1;
  std::vector<std::vector<int>> first(ni, std::vector<int>(np, 0)), cross = first;
  cv::Mat nearest = cv::Mat::zeros(reduced_size, CV_16UC1);
  for (const Ray& r : rays) {
    const int i = InstanceAt(inst, reduced_size, r.x, r.y);
    const int k = NearestPerson(r.hits, final_id);
    nearest.at<uint16_t>(r.y, r.x) = static_cast<uint16_t>(k);
    if (i == 0) continue;
    ++first[i][k];
    for (const uint16_t id : r.hits)
      if (final_id[id]) ++cross[i][final_id[id]];
  }
  std::vector<int> person_of(ni, 0);
  std::vector<uint8_t> paired(np, 0);
  for (const auto* count : {&first, &cross}) {
    struct Entry {
      int n, i, k;
    };
    std::vector<Entry> entries;
    for (int i = 1; i < ni; ++i)
      for (int k = 1; k < np; ++k)
        if ((*count)[i][k] > 0) entries.push_back({(*count)[i][k], i, k});
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
      return std::tie(b.n, a.i, a.k) < std::tie(a.n, b.i, b.k);
    });
    for (const Entry& e : entries)
      if (!person_of[e.i] && !paired[e.k]) person_of[e.i] = e.k, paired[e.k] = 1;
  }
  // Rays on which each person is nearest in the instance it holds most of (its
  // pair, then the instances split by it): a person whose pair is a fragment
  // (a foot, a hand) has most of its rays in the instance it merged with.
  std::vector<int> held(np, 0);
  for (int i = 1; i < ni; ++i)
    if (person_of[i]) held[person_of[i]] = std::max(held[person_of[i]], first[i][person_of[i]]);
  std::vector<std::vector<uint8_t>> split(ni, std::vector<uint8_t>(np, 0));
  for (int i = 1; i < ni; ++i) {
    if (person_of[i]) {
      for (int k = 1; k < np; ++k)
        split[i][k] = k == person_of[i] ||
                      (first[i][k] > held[k] &&
                       first[i][k] >= options.ground.min_split_share * first[i][person_of[i]]);
      for (int k = 1; k < np; ++k)
        if (k != person_of[i] && split[i][k]) held[k] = first[i][k];  // held by the split
    } else {
      person_of[i] = static_cast<int>(std::max_element(first[i].begin() + 1, first[i].end()) -
                                      first[i].begin());
      if (first[i][person_of[i]] == 0) person_of[i] = 0;
    }
  }
  // Nearest person per pixel at full resolution, for the merged instances.
  cv::Mat up;
  cv::resize(nearest, up, inst.size(), 0, 0, cv::INTER_NEAREST);
  const cv::Mat fg = inst > 0;
  const cv::Mat near_full =
      FillFromNearestId(up, fg, options.ground.occupancy_fill_fraction * inst.rows);
  cv::Mat out = cv::Mat::zeros(inst.size(), CV_16UC1);
  for (int y = 0; y < inst.rows; ++y)
    for (int x = 0; x < inst.cols; ++x) {
      const int i = inst.at<uint16_t>(y, x);
      if (i == 0 || person_of[i] == 0) continue;
      // Pixels far from any ray that meets a person (light, clutter
      // grouped with a person) are dropped.
      const int k = near_full.at<uint16_t>(y, x);
      if (k > 0) out.at<uint16_t>(y, x) = static_cast<uint16_t>(split[i][k] ? k : person_of[i]);
    }
  return out;
}

}  // namespace

Eigen::Vector3d RigUpDirection(const std::vector<Camera>& cameras) {
  U4D_CHECK(!cameras.empty(), "RigUpDirection: no cameras");
  // Image rows run down, and an upright camera's x axis is horizontal: up is
  // the direction most nearly orthogonal to every camera's x axis, with the
  // sign of the mean image "up" (-y axis).
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  Eigen::Vector3d image_up = Eigen::Vector3d::Zero();
  for (const Camera& c : cameras) {
    const Eigen::Matrix3d world_from_cam = c.cam_from_world.rotation.transpose();
    scatter += world_from_cam.col(0) * world_from_cam.col(0).transpose();
    image_up -= world_from_cam.col(1);
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  Eigen::Vector3d up = eig.eigenvectors().col(0);
  // All x axes (nearly) parallel: the orthogonal plane holds no single
  // direction; the mean image up is then the best guess.
  if (eig.eigenvalues()(1) < 0.05 * eig.eigenvalues()(2)) {
    U4D_CHECK(image_up.norm() > 1e-9, "RigUpDirection: the cameras' up directions cancel out");
    return image_up.normalized();
  }
  return up.dot(image_up) < 0 ? -up : up;
}

std::vector<cv::Mat> SeparatePeopleOnGround(const std::vector<Camera>& cameras,
                                            const std::vector<cv::Mat>& instances,
                                            const InitOptions& options, OccupancyMap* map,
                                            const std::vector<Eigen::Vector3d>& previous_people,
                                            bool instances_are_people) {
  options.Check();
  const int nv = static_cast<int>(cameras.size());
  U4D_CHECK(nv >= 2, "SeparatePeopleOnGround: needs at least 2 views, found {}", nv);
  U4D_CHECK(instances.size() == cameras.size(),
            "SeparatePeopleOnGround: {} instance images for {} cameras", instances.size(),
            cameras.size());
  std::vector<cv::Mat> masks(nv);
  for (int v = 0; v < nv; ++v) {
    cameras[v].Check(fmt::format("SeparatePeopleOnGround: camera {}", v));
    U4D_CHECK(!instances[v].empty() && instances[v].type() == CV_16UC1,
              "SeparatePeopleOnGround: instances {} must be a non-empty CV_16UC1 image", v);
    U4D_CHECK(instances[v].cols == cameras[v].width && instances[v].rows == cameras[v].height,
              "SeparatePeopleOnGround: instances {} are {}x{}, its camera {}x{}", v,
              instances[v].cols, instances[v].rows, cameras[v].width, cameras[v].height);
    masks[v] = instances[v] > 0;
  }

  OccupancyMap m = MakeGrid(cameras, options);
  // Reduced masks, as in the cross-view check.
  const ReducedMasks reduced = ReduceMasks(cameras, masks, options.ground.occupancy_max_side,
                                           options.cross_view.consistency_dilation_px);
  const std::vector<uint8_t> occupied = OccupiedVoxels(m, reduced, options);
  int candidates = 0;
  cv::Mat person = CandidatePeople(occupied, options, &m, &candidates);
  candidates = SplitByPrevious(previous_people, m, options, &person, candidates);
  std::vector<std::vector<Ray>> rays = CastRays(m, person, occupied, reduced);
  std::vector<uint16_t> final_id = RemovePhantoms(rays, person, candidates, options, &m);
  const auto cast_again = [&] {
    m.num_people = 0;
    rays = CastRays(m, person, occupied, reduced);
    final_id = RemovePhantoms(rays, person, candidates, options, &m);
  };
  if (instances_are_people) {
    const std::vector<std::vector<int>> splits =
        SplitByInstances(instances, rays, reduced, final_id, options, m, &person, &candidates);
    if (!splits.empty()) cast_again();
    if (UndoOverlappingSplits(splits, final_id, m, options, &person)) cast_again();
  }
  std::vector<cv::Mat> out(nv);
  tbb::parallel_for(0, nv, [&](int v) {
    out[v] = NameInstances(instances[v], rays[v], reduced.source[v].size(), final_id, m.num_people,
                           options);
  });
  m.positions = PeoplePositions(m);
  if (map != nullptr) *map = std::move(m);
  return out;
}

}  // namespace u4d
