// The search behind FindDistantPixels and FindGroundPixels (carve/ground_pixels.h):
// FindPixelsOnSurface of calib/distant_pixels.h, which declares it. Photos reduced, patches
// compared under the supposed surface's mapping and along each pixel's ray; plain regions judged
// by their rims in calib/plain_regions.cc.
#include "calib/distant_pixels.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <thread>

#include <glog/logging.h>
#include <opencv2/imgproc.hpp>

#include "calib/pixel.h"
#include "calib/plain_regions.h"
#include "calib/ray_box.h"
#include "calib/reduced_view.h"

namespace raycarve {

namespace {

// A match's correlation loses this much per standard deviation (of the photo's patch) between the
// two patches' mean colours.
constexpr double kMeanPenalty = 0.25;
// The volume's segment is searched with samples about this many pixels apart, first with every
// other row and column of the patch; the best sample and its two neighbours are then judged with
// the whole patch. (Where the search costs most: it ran 8.5 s of a 26 s carve of 25 photos of
// 1600 x 1200 judged whole and a pixel apart.)
constexpr double kSegmentStep = 1.5;

// A patch of RGB samples (k * 3 + channel), each channel less its mean: the means and the
// squared norm of what is left.
struct CentredPatch {
  std::vector<float> values;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double norm = 0.0;

  // Takes the samples' means out (values as sampled in, centred out).
  void Centre() {
    const size_t count = values.size() / 3;
    norm = 0.0;
    for (int c = 0; c < 3; ++c) {
      double sum = 0.0;
      for (size_t k = 0; k < count; ++k) sum += values[3 * k + c];
      mean[c] = sum / static_cast<double>(count);
      for (size_t k = 0; k < count; ++k) {
        values[3 * k + c] = static_cast<float>(values[3 * k + c] - mean[c]);
        norm += values[3 * k + c] * values[3 * k + c];
      }
    }
  }
};

// How well photo j sampled at `centre` + `offsets` matches the centred patch `a`: the zero-mean
// normalised correlation over the three channels (in colour, an edge between two colours does not
// match an edge between two others, as it would in grey), less kMeanPenalty times the difference
// of the means in units of a's standard deviation (a smooth ramp, a soft cloud's edge, correlates
// with itself shifted along it; its mean does not). -1 where a sample falls outside j's valid
// pixels or either patch is plain. `b` is the caller's buffer.
double Correlation(const CentredPatch& a, const ReducedView& j, const Eigen::Vector2d& centre,
                   const std::vector<Eigen::Vector2d>& offsets, CentredPatch* b) {
  if (!(a.norm > 1e-6)) return -1.0;
  b->values.resize(3 * offsets.size());
  for (size_t k = 0; k < offsets.size(); ++k) {
    if (!Sample(j, centre + offsets[k], &b->values[3 * k])) return -1.0;
  }
  b->Centre();
  if (!(b->norm > 1e-6)) return -1.0;
  double dot = 0.0;
  for (size_t k = 0; k < b->values.size(); ++k) dot += a.values[k] * b->values[k];
  const double a_deviation = std::sqrt(a.norm / static_cast<double>(b->values.size()));
  const double shift = (b->mean - a.mean).norm() / std::sqrt(3.0);
  return dot / std::sqrt(a.norm * b->norm) - kMeanPenalty * shift / a_deviation;
}

// One pair's geometry for one pixel: where the supposed surface and the ray's segment inside the
// volume land in photo j.
struct PairGeometry {
  int partner = -1;
  // Along the ray, up to where photo j tells it from the surface (min_parallax away from
  // on_surface): the segment searched ends there, and so does what j says is empty.
  double resolved_to = 0.0;
  Eigen::Vector2d on_surface;
  std::vector<Eigen::Vector2d> offsets;  // the patch's pixels on the surface, around on_surface
  std::vector<Eigen::Vector2d> segment;  // samples of the ray inside the volume, projected
};

bool ProjectInFront(const ReducedView& j, const Eigen::Vector4d& x, Eigen::Vector2d* pixel) {
  const Eigen::Vector3d h = j.P * x;
  if (!(h.z() > 1e-9)) return false;
  *pixel = h.hnormalized();
  return true;
}

bool ProjectPointInFront(const ReducedView& j, const Eigen::Vector3d& x, Eigen::Vector2d* pixel) {
  return ProjectInFront(j, Eigen::Vector4d(x.homogeneous()), pixel);
}

// A pixel's ray and where the supposed surface puts its patch: `points` per patch pixel, a
// homogeneous world point (w = 0: a direction, at infinity).
struct PixelRay {
  Eigen::Vector3d direction;  // unit
  double t0 = 0.0, t1 = 0.0;  // the part inside the volume that is compared with the surface
  double at = 0.0;            // where the centre's ray meets the surface
  std::vector<Eigen::Vector4d> points;
};

Eigen::Vector4d SurfacePoint(const Eigen::Vector3d& centre, const Eigen::Vector3d& direction, double at) {
  if (std::isinf(at)) return Eigen::Vector4d(direction.x(), direction.y(), direction.z(), 0.0);
  return (centre + at * direction).homogeneous();
}

// The farthest point of the ray's segment [t0, t1] that photo j sees at least `min_parallax`
// pixels from q (the surface's point), into *t1 (bisection in inverse distance, along which the
// point moves monotonically on j's epipolar line); false where no point of it is.
bool ResolvedEnd(const ReducedView& i, const ReducedView& j, const PixelRay& ray, const Eigen::Vector2d& q,
                 double min_parallax, double* t1) {
  const auto resolved = [&](double t) {
    Eigen::Vector2d pixel;
    return ProjectPointInFront(j, i.centre + t * ray.direction, &pixel) && (pixel - q).norm() >= min_parallax;
  };
  const double t_near = std::max(ray.t0, 1e-6);
  if (!(t_near < ray.t1) || !resolved(t_near)) return false;
  double near = 1.0 / t_near, far = 1.0 / ray.t1;  // inverse distances: resolved at near, not at far
  for (int k = 0; k < 40; ++k) {
    const double mid = 0.5 * (near + far);
    (resolved(1.0 / mid) ? near : far) = mid;
  }
  *t1 = 1.0 / near;
  return true;
}

bool PairFor(const ReducedView& i, const ReducedView& j, int partner, const PixelRay& ray,
             size_t centre_index, const DistantOptions& options, PairGeometry* pair) {
  Eigen::Vector2d q;
  if (!ProjectInFront(j, ray.points[centre_index], &q)) return false;  // behind photo j
  const double margin = options.patch_radius + 2.0;
  if (q.x() < margin || q.y() < margin || q.x() > j.rgb.cols - margin ||
      q.y() > j.rgb.rows - margin) {
    return false;
  }
  // The segment's far end must be told apart from the surface. For a surface at a finite
  // distance the segment is cut where photo j stops telling it apart (the ray is cleared that far
  // only); for the sky the whole segment must be (its ray is cleared through the volume).
  Eigen::Vector2d far;
  if (!ProjectPointInFront(j, i.centre + ray.t1 * ray.direction, &far)) return false;
  double t1 = ray.t1;
  if ((far - q).norm() < options.min_parallax) {
    if (std::isinf(ray.at) || !ResolvedEnd(i, j, ray, q, options.min_parallax, &t1)) return false;
    if (!ProjectPointInFront(j, i.centre + t1 * ray.direction, &far)) return false;
  }
  pair->resolved_to = t1;
  pair->partner = partner;
  pair->on_surface = q;
  pair->offsets.clear();
  for (const Eigen::Vector4d& x : ray.points) {
    Eigen::Vector2d pixel;
    if (!ProjectInFront(j, x, &pixel)) return false;
    pair->offsets.push_back(pixel - q);
  }
  // Samples uniform in inverse distance (about uniform in the image), about a pixel apart, of the
  // part of the segment in front of photo j.
  pair->segment.clear();
  Eigen::Vector2d near_pixel = Eigen::Vector2d::Zero();
  double t_near = std::max(ray.t0, 1e-6);
  while (t_near < t1 && !ProjectPointInFront(j, i.centre + t_near * ray.direction, &near_pixel)) {
    t_near = t_near * 2.0 + 1e-6;
  }
  if (!(t_near < t1)) return true;
  const double length = (near_pixel - far).norm();
  const int count = std::clamp(static_cast<int>(std::ceil(length / kSegmentStep)) + 1, 2, 128);
  for (int k = 0; k < count; ++k) {
    const double s = 1.0 / t1 + (1.0 / t_near - 1.0 / t1) * k / (count - 1);
    Eigen::Vector2d pixel;
    if (ProjectPointInFront(j, i.centre + ray.direction / s, &pixel)) pair->segment.push_back(pixel);
  }
  return true;
}

// The ray of pixel p of photo i (COLMAP coordinates) and the surface's points for its patch; false
// where the surface says nothing of it or it does not cross the volume in front of the surface.
bool RayOf(const ReducedView& i, const Eigen::Vector2d& p, const Eigen::AlignedBox3d& box,
           const std::vector<Eigen::Vector2d>& patch, const SupposedSurface& surface,
           PixelRay* ray) {
  const Eigen::Matrix3d pixel_to_world = i.R.transpose() * i.K.inverse();
  ray->direction = (pixel_to_world * p.homogeneous()).normalized();
  double clear_to = 0.0;
  if (!surface(i.centre, ray->direction, &ray->at, &clear_to)) return false;
  if (!ClipRayToBox(i.centre, ray->direction, box, &ray->t0, &ray->t1)) return false;
  ray->t1 = std::min(ray->t1, clear_to);
  if (!(ray->t1 > ray->t0)) return false;
  ray->points.clear();
  for (const Eigen::Vector2d& o : patch) {
    const Eigen::Vector3d d = (pixel_to_world * (p + o).homogeneous()).normalized();
    double at = 0.0, unused = 0.0;
    if (!surface(i.centre, d, &at, &unused)) return false;
    ray->points.push_back(SurfacePoint(i.centre, d, at));
  }
  return true;
}

// Judges the textured pixels of one photo against the others (one per thread at a time).
class PhotoJudge {
 public:
  PhotoJudge(const std::vector<ReducedView>& views, int v, const Eigen::AlignedBox3d& box,
             const std::vector<Eigen::Vector2d>& patch, const SupposedSurface& surface,
             const DistantOptions& options)
      : views_(views), i_(views[v]), box_(box), patch_(patch), surface_(surface), options_(options) {
    // Partners: the other photos, farthest first (the most parallax).
    for (int w = 0; w < static_cast<int>(views.size()); ++w) {
      if (w != v) partners_.push_back(w);
    }
    std::stable_sort(partners_.begin(), partners_.end(), [&](int x, int y) {
      return (views[x].centre - i_.centre).squaredNorm() > (views[y].centre - i_.centre).squaredNorm();
    });
    // The coarse search's samples: every other row and column of the patch.
    const int side = 2 * options.patch_radius + 1;
    for (size_t k = 0; k < patch.size(); ++k) {
      if ((k % side) % 2 == 0 && (k / side) % 2 == 0) kept_.push_back(k);
    }
  }

  // The verdict on pixel p, whose centred patch is `a`: 1 on the surface, -1 nearer, 0 neither.
  // `ray` is p's ray (RayOf). On the surface, *cleared_to is how far along the ray
  // min_agreeing_views of the photos that agree tell it from the surface (the ray's segment end,
  // or nearer where a photo resolves less of it).
  int Verdict(const PixelRay& ray, const CentredPatch& a, double* cleared_to) {
    // First the cheap test on the surface, on up to max_partners photos.
    pairs_.clear();
    on_surface_.clear();
    int matched = 0;
    const size_t centre_index = patch_.size() / 2;
    for (int partner : partners_) {
      if (static_cast<int>(pairs_.size()) >= options_.max_partners) break;
      PairGeometry pair;
      if (!PairFor(i_, views_[partner], partner, ray, centre_index, options_, &pair)) continue;
      const double c = Correlation(a, views_[partner], pair.on_surface, pair.offsets, &buffer_);
      on_surface_.push_back(c);
      if (c >= options_.min_correlation) ++matched;
      pairs_.push_back(std::move(pair));
    }
    if (matched < options_.min_agreeing_views) return 0;
    // Then the volume's segment, in every photo asked: one that matches inside clearly better is
    // a veto; a match on the surface counts where nothing inside comes near it.
    coarse_.values.clear();
    for (size_t k : kept_) {
      coarse_.values.insert(coarse_.values.end(), {a.values[3 * k], a.values[3 * k + 1], a.values[3 * k + 2]});
    }
    coarse_.Centre();
    coarse_.mean += a.mean;  // a's values were centred already
    resolved_.clear();
    for (size_t k = 0; k < pairs_.size(); ++k) {
      const double inside = BestInside(a, pairs_[k]);
      if (inside >= options_.min_correlation && inside - on_surface_[k] >= options_.min_advantage) {
        return -1;
      }
      if (on_surface_[k] >= options_.min_correlation &&
          on_surface_[k] - inside >= options_.min_advantage) {
        resolved_.push_back(pairs_[k].resolved_to);
      }
    }
    const int agreeing = static_cast<int>(resolved_.size());
    if (agreeing < options_.min_agreeing_views) return 0;
    std::nth_element(resolved_.begin(), resolved_.begin() + (options_.min_agreeing_views - 1), resolved_.end(),
                     std::greater<double>());
    *cleared_to = resolved_[options_.min_agreeing_views - 1];
    return 1;
  }

  // Per other photo, its brightness against this one's, per channel: the median ratio of the
  // colours where this photo's pixels found on the surface (`found`) fall in it, as an automatic
  // exposure sets them (1 where fewer than kMinGainSamples of them fall inside it).
  void EstimateGains(const std::vector<Eigen::Vector2d>& found) {
    gains_.assign(views_.size(), Eigen::Vector3d::Ones());
    // The sampled pixels' surface points and colours, once for every partner.
    std::vector<Eigen::Vector4d> points;
    std::vector<Eigen::Vector3f> colours;
    PixelRay ray;
    Eigen::Vector3f colour;
    for (size_t k = 0; k < found.size(); k += std::max<size_t>(1, found.size() / kGainSamples)) {
      if (RayOf(i_, found[k], box_, {Eigen::Vector2d::Zero()}, surface_, &ray) &&
          Mean3x3(i_, found[k], colour.data())) {
        points.push_back(ray.points[0]);
        colours.push_back(colour);
      }
    }
    std::vector<double> ratios[3];
    for (int partner : partners_) {
      for (std::vector<double>& r : ratios) r.clear();
      for (size_t k = 0; k < points.size(); ++k) {
        Eigen::Vector2d q;
        if (!ProjectInFront(views_[partner], points[k], &q) ||
            !Mean3x3(views_[partner], q, colour.data())) {
          continue;
        }
        for (int c = 0; c < 3; ++c) {
          if (colours[k][c] >= kMinGainLevel && colour[c] >= kMinGainLevel) {
            ratios[c].push_back(colour[c] / colours[k][c]);
          }
        }
      }
      for (int c = 0; c < 3; ++c) {
        if (static_cast<int>(ratios[c].size()) < kMinGainSamples) continue;
        std::nth_element(ratios[c].begin(), ratios[c].begin() + ratios[c].size() / 2, ratios[c].end());
        gains_[partner][c] = ratios[c][ratios[c].size() / 2];
      }
    }
  }

  // Whether the photos asked (up to max_partners that tell `ray` from the surface) see, where the
  // surface puts the ray's point, the colour `colour` (3 x 3 pixels' mean, within `tolerance` after
  // their gain): false where most of them see another.
  bool SeenOnSurface(const PixelRay& ray, const float* colour, double tolerance) {
    int agree = 0, asked = 0;
    for (int partner : partners_) {
      if (asked >= options_.max_partners) break;
      PairGeometry pair;
      float mean[3];
      if (!PairFor(i_, views_[partner], partner, ray, 0, options_, &pair) ||
          !Mean3x3(views_[partner], pair.on_surface, mean)) {
        continue;
      }
      ++asked;
      double squared = 0.0;
      for (int c = 0; c < 3; ++c) {
        const double gain = gains_.empty() ? 1.0 : gains_[partner][c];
        squared += (mean[c] - gain * colour[c]) * (mean[c] - gain * colour[c]);
      }
      agree += std::sqrt(squared / 3.0) <= tolerance;
    }
    return asked < options_.min_agreeing_views || 2 * agree >= asked;
  }

 private:
  // The gains: from up to this many pixels found, channels at least this bright in both photos,
  // and at least this many ratios.
  static constexpr size_t kGainSamples = 400;
  static constexpr float kMinGainLevel = 8.0f;
  static constexpr int kMinGainSamples = 20;

  // The best match on the pair's segment: searched with the coarse patch, then the whole patch
  // at the best sample and its two neighbours. -1 where none can be judged.
  double BestInside(const CentredPatch& a, const PairGeometry& pair) {
    const ReducedView& j = views_[pair.partner];
    coarse_offsets_.clear();
    for (size_t k : kept_) coarse_offsets_.push_back(pair.offsets[k]);
    const auto away = [&](int s) {
      return s >= 0 && s < static_cast<int>(pair.segment.size()) &&
             (pair.segment[s] - pair.on_surface).norm() >= options_.min_parallax;
    };
    double best = -2.0;
    int best_sample = -1;
    for (int s = 0; s < static_cast<int>(pair.segment.size()); ++s) {
      if (!away(s)) continue;
      const double c = Correlation(coarse_, j, pair.segment[s], coarse_offsets_, &buffer_);
      if (c > best) {
        best = c;
        best_sample = s;
      }
    }
    double inside = -1.0;
    for (int s = best_sample - 1; best_sample >= 0 && s <= best_sample + 1; ++s) {
      if (away(s)) inside = std::max(inside, Correlation(a, j, pair.segment[s], pair.offsets, &buffer_));
    }
    return inside;
  }

  const std::vector<ReducedView>& views_;
  const ReducedView& i_;
  const Eigen::AlignedBox3d& box_;
  const std::vector<Eigen::Vector2d>& patch_;
  const SupposedSurface& surface_;
  const DistantOptions& options_;
  std::vector<int> partners_;
  std::vector<Eigen::Vector3d> gains_;  // EstimateGains
  std::vector<size_t> kept_;
  // Scratch, kept between pixels.
  std::vector<PairGeometry> pairs_;
  std::vector<double> on_surface_;
  std::vector<double> resolved_;  // the agreeing pairs' resolved_to
  CentredPatch coarse_, buffer_;
  std::vector<Eigen::Vector2d> coarse_offsets_;
};

// Whether the patch (raw RGB samples) is textured: its grey standard deviation reaches `texture`
// (the colour patch's is its upper bound).
bool PatchTextured(const std::vector<float>& values, double texture) {
  const size_t count = values.size() / 3;
  double mean = 0.0, square = 0.0;
  for (size_t k = 0; k < count; ++k) {
    const double grey = 0.299 * values[3 * k] + 0.587 * values[3 * k + 1] + 0.114 * values[3 * k + 2];
    mean += grey;
    square += grey * grey;
  }
  mean /= static_cast<double>(count);
  return square / static_cast<double>(count) - mean * mean >= texture * texture;
}

// Whether each quadrant of the patch (rows and columns <= 0 and >= 0 of its centre, raw RGB
// samples in row order) is textured (PatchTextured).
bool QuadrantsTextured(const std::vector<float>& values, int radius, double texture) {
  const int side = 2 * radius + 1;
  thread_local std::vector<float> quadrant;  // kept between calls: judged for every textured pixel
  for (int qy = 0; qy < 2; ++qy) {
    for (int qx = 0; qx < 2; ++qx) {
      quadrant.clear();
      for (int y = qy * radius; y <= qy * radius + radius; ++y) {
        for (int x = qx * radius; x <= qx * radius + radius; ++x) {
          const size_t k = static_cast<size_t>(y * side + x);
          quadrant.insert(quadrant.end(), {values[3 * k], values[3 * k + 1], values[3 * k + 2]});
        }
      }
      if (!PatchTextured(quadrant, texture)) return false;
    }
  }
  return true;
}

// One photo's verdicts (DistantPixels::masks), counts and rays.
struct PhotoVerdicts {
  std::vector<DistantRay> rays;
  cv::Mat mask;
  int64_t textured = 0, found = 0, nearer = 0, grown = 0, grown_refused = 0;
};

// Judges photo v's textured pixels (every `stride`) against the others, then its plain regions.
// `seen`: the photo's own pixels of sparse points inside the volume.
PhotoVerdicts JudgePhoto(const std::vector<ReducedView>& reduced, int v, const Eigen::AlignedBox3d& box,
                         const std::vector<Eigen::Vector2d>& patch, const SupposedSurface& surface,
                         const DistantOptions& options, const std::vector<Eigen::Vector2d>& seen) {
  const ReducedView& i = reduced[v];
  const int r = options.patch_radius;
  PhotoVerdicts out;
  out.mask = cv::Mat(i.rgb.size(), CV_8UC1, cv::Scalar(0));
  PhotoJudge judge(reduced, v, box, patch, surface, options);
  CentredPatch a;
  a.values.resize(3 * patch.size());
  PixelRay ray;
  // A ray found, cleared to `cleared_to` (its own or, for a pixel of a found pixel's stride cell,
  // that pixel's share of the way to the surface).
  const auto add_ray = [&](const PixelRay& found, double cleared_to) {
    const double length = std::isinf(found.at) ? std::numeric_limits<double>::infinity()
                                               : std::min(found.t1, cleared_to);
    out.rays.push_back(DistantRay{v, found.direction, length});
  };
  for (int row = r + 1; row < i.rgb.rows - r - 1; row += options.stride) {
    for (int col = r + 1; col < i.rgb.cols - r - 1; col += options.stride) {
      const Eigen::Vector2d p = PixelCentre(row, col);
      bool ok = true;
      for (size_t k = 0; k < patch.size() && ok; ++k) ok = Sample(i, p + patch[k], &a.values[3 * k]);
      if (!ok || !PatchTextured(a.values, i.texture)) continue;
      if (options.textured_quadrants && !QuadrantsTextured(a.values, r, i.texture)) continue;
      ++out.textured;
      if (!RayOf(i, p, box, patch, surface, &ray)) {
        out.mask.at<uint8_t>(row, col) = kUndecided;
        continue;
      }
      a.Centre();
      double cleared_to = ray.t1;
      const int verdict = judge.Verdict(ray, a, &cleared_to);
      out.mask.at<uint8_t>(row, col) = verdict > 0 ? kDistantJudged : verdict < 0 ? kNearer : kUndecided;
      if (verdict < 0) ++out.nearer;
      if (verdict <= 0) continue;
      ++out.found;
      add_ray(ray, cleared_to);
      if (!options.cell_rays) continue;
      const double share = std::isinf(ray.at) ? 1.0 : cleared_to / ray.at;
      PixelRay neighbour;  // the pixels of the stride cell that p stands for
      for (int dy = 0; dy < options.stride; ++dy) {
        for (int dx = 0; dx < options.stride; ++dx) {
          if ((dx != 0 || dy != 0) && RayOf(i, PixelCentre(row + dy, col + dx), box, {}, surface, &neighbour)) {
            add_ray(neighbour, share * neighbour.at);
          }
        }
      }
    }
  }
  if (options.grow_plain_regions) {
    if (options.check_grown_colour) {
      std::vector<Eigen::Vector2d> found;
      for (int row = 0; row < out.mask.rows; ++row) {
        for (int col = 0; col < out.mask.cols; ++col) {
          if (out.mask.at<uint8_t>(row, col) == kDistantJudged) found.push_back(PixelCentre(row, col));
        }
      }
      judge.EstimateGains(found);
    }
    const std::vector<Eigen::Vector2d> centre = {Eigen::Vector2d::Zero()};
    for (const Eigen::Vector2d& p : GrowIntoPlainRegions(Grey(i), i.valid, i.texture, i.factor, options,
                                                         seen, &out.mask, &out.grown)) {
      if (!RayOf(i, p, box, centre, surface, &ray)) continue;
      // A plain patch matches anything plain: its colour is what is asked. Within the photo's
      // plain spread (a patch under `texture` is plain), after the other photo's gain.
      float colour[3];
      if (options.check_grown_colour &&
          (!Mean3x3(i, p, colour) || !judge.SeenOnSurface(ray, colour, i.texture))) {
        ++out.grown_refused;
        continue;
      }
      add_ray(ray, ray.t1);
    }
  }
  return out;
}

}  // namespace

DistantPixels FindPixelsOnSurface(const std::vector<CalibratedView>& views,
                                  const Eigen::AlignedBox3d& box,
                                  const DistantOptions& options,
                                  const SupposedSurface& surface,
                                  const std::vector<std::vector<Eigen::Vector2d>>& observations) {
  const auto start = std::chrono::steady_clock::now();
  std::string reason;
  CHECK(options.IsValid(&reason)) << reason;
  const int n = static_cast<int>(views.size());
  std::vector<ReducedView> reduced(n);
  for (int v = 0; v < n; ++v) reduced[v] = ReducedViewOf(views[v], options);
  const int r = options.patch_radius;
  std::vector<Eigen::Vector2d> patch;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) patch.emplace_back(dx, dy);
  }
  std::vector<PhotoVerdicts> photos(n);
  std::atomic<int> next{0};
  auto work = [&] {
    static const std::vector<Eigen::Vector2d> kNone;
    for (int v = next++; v < n; v = next++) {
      photos[v] = JudgePhoto(reduced, v, box, patch, surface, options,
                             v < static_cast<int>(observations.size()) ? observations[v] : kNone);
    }
  };
  const int threads = std::max(1, std::min(n, options.num_threads > 0
                                                  ? options.num_threads
                                                  : static_cast<int>(std::thread::hardware_concurrency())));
  std::vector<std::thread> workers;
  for (int t = 1; t < threads; ++t) workers.emplace_back(work);
  work();
  for (std::thread& worker : workers) worker.join();
  DistantPixels result;
  for (int v = 0; v < n; ++v) {
    PhotoVerdicts& photo = photos[v];
    result.rays.insert(result.rays.end(), photo.rays.begin(), photo.rays.end());
    result.textured += photo.textured;
    result.distant += photo.found;
    result.nearer += photo.nearer;
    result.grown += photo.grown;
    result.grown_refused += photo.grown_refused;
    result.factors.push_back(reduced[v].factor);
    result.masks.push_back(std::move(photo.mask));
  }
  result.photos_judged = static_cast<int>(result.masks.size());
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace raycarve
