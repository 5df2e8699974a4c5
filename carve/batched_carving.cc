// IncrementalCarver's batched carving (CarveOptions::batch_voxels): a batch of queued voxels
// judged at once on every thread, then carved together.
#include "carve/incremental_carver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include <glog/logging.h>

#include "carve/free_space.h"
#include "carve/item_buffer_visibility.h"
#include "carve/layered_depth_visibility.h"
#include "carve/patch_correlation.h"
#include "carve/ray_image.h"


#include "carve/carver_internal.h"

namespace raycarve {
namespace {

// between two sortings of the views by their cost (SortViewsByCost).
constexpr int kClaimChunk = 8;
// Finding Vis: how many voxels ahead their rays and photo rows are fetched.
constexpr int kPrefetchAhead = 3;
constexpr int kSortTasks = 64;


// Calls work(view) for every view on `workers`, the groups claiming views one at a time: each
// group first its own (view v belongs to group v mod G, so that a view's rays stay in one core's
// cache from task to task), then any left, in `order` (the costliest first). Each group first
// calls lead(group), which must touch nothing another group's calls do (while the calling
// thread's group 0 leads, the others claim the views it would have taken).
template <typename Work, typename Lead>
void ClaimViews(ViewWorkers& workers, const std::vector<int>& order,
                std::atomic<uint8_t>* claimed, Work work, Lead lead) {
  for (int view : order) claimed[view].store(0, std::memory_order_relaxed);
  auto task = [&](int group) {
    lead(group);
    for (int pass = 0; pass < 2; ++pass) {
      for (int view : order) {
        if (pass == 0 && workers.GroupOf(view) != group) continue;
        if (claimed[view].load(std::memory_order_relaxed) != 0 ||
            claimed[view].exchange(1, std::memory_order_relaxed) != 0) {
          continue;
        }
        work(view);
      }
      if (workers.num_groups() == 1) break;
    }
  };
  workers.Run(task);
}

// Removes from `values` [0, n) every value seen earlier in it, keeping the order of the rest;
// returns how many are left. Neighbouring pixels' rays mostly reach the same voxels, and queueing
// a voxel twice in a row is a no-op: done on the workers, this spares the serial queueing most of
// its work without changing what is queued. (Short runs checked in full, longer ones against
// the previous value only.)
size_t KeepFirstOccurrences(int64_t* values, size_t n) {
  constexpr size_t kFullCheck = 64;
  size_t kept = 0;
  for (size_t i = 0; i < n; ++i) {
    bool seen = false;
    if (n <= kFullCheck) {
      for (size_t j = 0; j < kept && !seen; ++j) seen = values[j] == values[i];
    } else {
      seen = kept > 0 && values[kept - 1] == values[i];
    }
    if (!seen) values[kept++] = values[i];
  }
  return kept;
}

}  // namespace

void IncrementalCarver::RunViewGroups(const std::vector<PixelRef>* advance,
                                      int64_t vis_voxel,
                                      bool gather,
                                      bool advance_found) {
  CHECK(!advance_found || (advance == nullptr && vis_voxel >= 0));
  const int num_views = static_cast<int>(views_.size());
  // `advance` is in view order: view v's pixels are [advance_begin_[v], advance_begin_[v + 1]).
  if (advance != nullptr) {
    advance_begin_.assign(num_views + 1, 0);
    for (const PixelRef& ref : *advance) ++advance_begin_[ref.view + 1];
    for (int view = 0; view < num_views; ++view) advance_begin_[view + 1] += advance_begin_[view];
  }
  const Eigen::Vector3i vis_coordinates =
      vis_voxel >= 0 ? volume_.grid().Voxel(vis_voxel) : Eigen::Vector3i::Zero();
  auto task = [&](int group) {
    GroupBuffers& buffers = groups_[group];
    buffers.changed.clear();
    buffers.vis.clear();
    buffers.stats.clear();
    buffers.changed_end.clear();
    buffers.vis_end.clear();
    buffers.stats_end.clear();
    for (int view = group; view < num_views; view += workers_.num_groups()) {
      // Stepping the rays before finding Vis: the Vis found is that after this carving.
      if (advance != nullptr) {
        ray_visibility_->AdvanceRays(advance->data() + advance_begin_[view],
                                     advance->data() + advance_begin_[view + 1], &buffers.changed);
      }
      if (vis_voxel >= 0) {
        const size_t first = buffers.vis.size();
        ray_visibility_->ComputeVisInView(vis_coordinates, view, &buffers.vis);
        if (advance_found) {
          ray_visibility_->AdvanceRays(buffers.vis.data() + first,
                                       buffers.vis.data() + buffers.vis.size(), &buffers.changed);
        }
        if (gather) {
          GatherColours(views_, buffers.vis.data() + first,
                        buffers.vis.data() + buffers.vis.size(), &buffers.stats);
        }
      }
      buffers.changed_end.push_back(buffers.changed.size());
      buffers.vis_end.push_back(buffers.vis.size());
      buffers.stats_end.push_back(buffers.stats.size());
    }
  };
  workers_.Run(task);
  // Merged view by view: exactly what one thread would have produced.
  if (vis_voxel >= 0) {
    vis_.clear();
    if (gather) stats_.clear();
  }
  const int num_groups = workers_.num_groups();
  for (int view = 0; view < num_views; ++view) {
    const GroupBuffers& buffers = groups_[view % num_groups];
    const int k = view / num_groups;  // the view's place in its group
    const auto append = [k](const auto& from, const std::vector<size_t>& ends, auto* to) {
      const size_t begin = k == 0 ? 0 : ends[k - 1];
      to->insert(to->end(), from.begin() + begin, from.begin() + ends[k]);
    };
    append(buffers.changed, buffers.changed_end, &changed_);
    if (vis_voxel >= 0) {
      append(buffers.vis, buffers.vis_end, &vis_);
      if (gather) append(buffers.stats, buffers.stats_end, &stats_);
    }
  }
}



void IncrementalCarver::FormBatch(Batch* batch) {
  batch->Clear();
  while (static_cast<int>(batch->entries.size()) < batch_voxels_) {
    if (queue_.empty()) {
      // The arrivals still to be queued go behind what was queued: needed only now.
      if (pending_slot_ < 0) break;
      QueuePendingArrivals();
      continue;
    }
    const int64_t voxel = queue_.front();
    queue_.pop_front();
    if (!volume_.IsSolid(voxel)) {
      queued_[voxel >> 6] &= ~(uint64_t{1} << (voxel & 63));
      continue;
    }
    batch->Add(voxel, volume_.grid());
  }
}

void IncrementalCarver::QueuePendingArrivals() {
  if (pending_slot_ < 0) return;
  const int slot = pending_slot_;
  pending_slot_ = -1;
  // Carved voxel by carved voxel, view by view: the same order for any number of groups. Each
  // view's runs are walked alongside, in carved order.
  const int num_views = static_cast<int>(views_.size());
  std::vector<size_t>& next_run = pending_next_run_;
  next_run.assign(num_views, 0);
  if (workers_.num_groups() > 1) {
    // Written by the views' threads; read below a little of every view at a time.
    for (int view = 0; view < num_views; ++view) {
      const ViewOutput& output = view_outputs_[view];
      const uint32_t num_runs = output.num_runs[slot];
      if (num_runs == 0) continue;
      PrefetchForReading(output.runs[slot], num_runs * sizeof(ReachedRun));
      PrefetchForReading(output.reached[slot],
                         output.runs[slot][num_runs - 1].end * sizeof(int64_t));
    }
  }
  for (size_t j = 0; j < pending_carved_; ++j) {
    for (int view = 0; view < num_views; ++view) {
      const ViewOutput& output = view_outputs_[view];
      const ReachedRun* runs = output.runs[slot];
      const size_t run = next_run[view];
      if (run == output.num_runs[slot] || runs[run].j != j) continue;
      next_run[view] = run + 1;
      const int64_t* reached = output.reached[slot];
      const uint32_t first = run == 0 ? 0 : runs[run - 1].end;
      for (uint32_t p = first; p < runs[run].end; ++p) {
        const int64_t voxel = reached[p];
        // A voxel carved since it was reached was queued then and has since been taken from the
        // queue by FormBatch, which found it empty (see StepBatch): not queued again.
        if (volume_.IsSolid(voxel)) Enqueue(voxel);
      }
    }
  }
  pending_carved_ = 0;
}

// One function, not split: it is the view threads' inner loop (stepping the rays, then finding
// Vis batch by batch), whose buffers, prefetches and timers are measured as one (docs/studies/threads.md).
void IncrementalCarver::RunViewTask(Batch* carving, int carving_slot, Batch* finding,
                                    int finding_slot) {
  auto work = [&](int view) {
    const Clock::time_point start = Clock::now();
    ViewBuffers& buffers = view_buffers_[view];
    if (carving != nullptr) {
      const std::vector<PixelRef>& vis = buffers.vis[carving_slot];
      const std::vector<Span>& spans = buffers.spans[carving_slot];
      std::vector<int64_t>& reached = buffers.reached[carving_slot];
      std::vector<ReachedRun>& runs = buffers.reached_runs[carving_slot];
      if (workers_.num_groups() > 1) {
        // The calling thread read both when it queued the arrivals of the batch last carved
        // from this slot.
        PrefetchForWriting(reached.data(), reached.size() * sizeof(int64_t));
        PrefetchForWriting(runs.data(), runs.size() * sizeof(ReachedRun));
      }
      reached.clear();
      runs.clear();
      for (size_t j = 0; j < batch_carved_.size(); ++j) {
        const int k = batch_carved_[j];
        if (spans[k].begin == spans[k].end) continue;  // most views see none of a voxel
        const size_t begin = reached.size();
        ray_visibility_->AdvanceRaysFrom(carving->coordinates[k],
                                         vis.data() + spans[k].begin, vis.data() + spans[k].end,
                                         &reached);
        const size_t kept = KeepFirstOccurrences(reached.data() + begin, reached.size() - begin);
        reached.resize(begin + kept);
        if (kept > 0) {
          runs.push_back({static_cast<uint32_t>(j), static_cast<uint32_t>(begin + kept)});
        }
      }
      ViewOutput& output = view_outputs_[view];
      output.reached[carving_slot] = reached.data();
      output.runs[carving_slot] = runs.data();
      output.num_runs[carving_slot] = static_cast<uint32_t>(runs.size());
    }
    if (finding != nullptr) {
      std::vector<PixelRef>& vis = buffers.vis[finding_slot];
      std::vector<Span>& spans = buffers.spans[finding_slot];
      std::vector<BatchHit>& hits = buffers.hits[finding_slot];
      if (workers_.num_groups() > 1) {
        // The calling thread read them when it judged the batch last found in this slot.
        PrefetchForWriting(hits.data(), hits.size() * sizeof(BatchHit));
      }
      vis.clear();
      hits.clear();
      const int num_entries = static_cast<int>(finding->entries.size());
      spans.assign(num_entries, Span{});  // empty, unless the view sees the voxel
      // The footprints first, so that the rays and photo rows of the voxels a few ahead can be
      // fetched while a voxel's are scanned: the scans wait on memory more than they compute.
      // Most views see none of a voxel (no ray of theirs ends in it: an empty footprint); only
      // the others are scanned, and fetched ahead.
      std::vector<Footprint>& footprints = buffers.footprints;
      std::vector<int>& seen = buffers.seen;
      footprints.resize(num_entries);
      seen.clear();
      for (int k = 0; k < num_entries; ++k) {
        footprints[k] = ray_visibility_->VisFootprint(finding->coordinates[k], view);
        if (!footprints[k].empty()) seen.push_back(k);
      }
      const cv::Mat& photo = views_[view].image;
      const uint8_t* image = photo.data;
      const int num_seen = static_cast<int>(seen.size());
      for (int i = 0; i < num_seen; ++i) {
        if (i + kPrefetchAhead < num_seen) {
          const Footprint& ahead = footprints[seen[i + kPrefetchAhead]];
          ray_visibility_->PrefetchRays(ahead, view);
          for (int row = ahead.row_min; row <= ahead.row_max; ++row) {
            const uint8_t* line = photo.ptr<uint8_t>(row);
            __builtin_prefetch(line + 3 * ahead.col_min);
            __builtin_prefetch(line + 3 * ahead.col_max + 2);
          }
        }
        const int k = seen[i];
        Span& span = spans[k];
        span.begin = static_cast<uint32_t>(vis.size());
        ray_visibility_->AppendVis(footprints[k], finding->coordinates[k], view, &vis);
        span.end = static_cast<uint32_t>(vis.size());
        if (span.end == span.begin) continue;
        for (uint32_t first = span.begin; first < span.end; first += kMaxHitPixels) {
          const uint32_t last = std::min(span.end, first + kMaxHitPixels);
          uint32_t sum[3] = {0, 0, 0}, sum_squares[3] = {0, 0, 0};
          for (uint32_t p = first; p < last; ++p) {
            const uint8_t* rgb = image + 3 * static_cast<size_t>(vis[p].pixel);
            for (int c = 0; c < 3; ++c) {
              sum[c] += rgb[c];
              sum_squares[c] += uint32_t{rgb[c]} * rgb[c];
            }
          }
          BatchHit& hit = hits.emplace_back();
          hit.k = k;
          hit.count = last - first;
          for (int c = 0; c < 3; ++c) {
            hit.sum[c] = sum[c];
            hit.sum_squares[c] = sum_squares[c];
          }
        }
      }
      ViewOutput& output = view_outputs_[view];
      output.hits[finding_slot] = hits.data();
      output.num_hits[finding_slot] = static_cast<uint32_t>(hits.size());
    }
    buffers.nanoseconds += ElapsedNanoseconds(start);
  };
  // The calling thread queues the last task's arrivals (in the other slot) while the others
  // take its views.
  if (pending_slot_ == carving_slot) QueuePendingArrivals();
  ClaimViews(workers_, claim_order_, view_claimed_.get(), work,
             [this](int group) {
               if (group == 0) QueuePendingArrivals();
             });
  if (++tasks_since_sort_ >= kSortTasks) SortViewsByCost();
}

void IncrementalCarver::SortViewsByCost() {
  tasks_since_sort_ = 0;
  std::stable_sort(claim_order_.begin(), claim_order_.end(), [this](int a, int b) {
    return view_buffers_[a].nanoseconds > view_buffers_[b].nanoseconds;
  });
  for (ViewBuffers& buffers : view_buffers_) buffers.nanoseconds = 0;
}

// One function, not split: the serial judging's two passes over the views' hits share the
// counts they build (each view's hits counted, then placed), measured as one (docs/studies/threads.md).
void IncrementalCarver::JudgeEntries(Batch* batch, int slot, bool colouring) {
  const int num_views = static_cast<int>(views_.size());
  // Judges entries [first, last). Their sums are first gathered view by view (each view's hits
  // are in batch order, a voxel's consecutive), into each entry's views in view order: read so,
  // each view's hits are one stream that the processor fetches ahead, where walking the entries
  // and for each every view's next hit waited on memory (22% of the judging's time at one
  // instruction) and branched unpredictably (a view sees about a third of the voxels).
  auto judge = [&](int first, int last, int group) {
    GroupBuffers& own = groups_[group];
    std::vector<ViewColourStats>& stats = own.stats;
    std::vector<ViewColourStats>& view_sums = own.view_sums;
    std::vector<uint32_t>& begin = own.view_sums_begin;
    std::vector<uint32_t>& count = own.view_sums_count;
    const int num_entries = last - first;
    auto hits_from = [&](int view) {
      const ViewOutput& output = view_outputs_[view];
      const BatchHit* end = output.hits[slot] + output.num_hits[slot];
      const BatchHit* hit =
          first == 0 ? output.hits[slot]
                     : std::lower_bound(output.hits[slot], end, first,
                                        [](const BatchHit& h, int key) { return h.k < key; });
      return std::make_pair(hit, end);
    };
    // The views of each entry (a voxel's hits in one view are consecutive)...
    count.assign(num_entries + 1, 0);
    if (first == 0 && workers_.num_groups() > 1) {
      // Written by the views' threads: fetched at once rather than a view's stream at a time.
      for (int view = 0; view < num_views; ++view) {
        const ViewOutput& output = view_outputs_[view];
        PrefetchForReading(output.hits[slot], output.num_hits[slot] * sizeof(BatchHit));
      }
    }
    for (int view = 0; view < num_views; ++view) {
      auto [hit, end] = hits_from(view);
      for (int previous = -1; hit != end && hit->k < last; ++hit) {
        count[hit->k - first] += hit->k != previous;
        previous = hit->k;
      }
    }
    begin.resize(num_entries + 1);
    uint32_t total = 0;
    for (int i = 0; i <= num_entries; ++i) {
      begin[i] = total;
      total += count[i];
      count[i] = 0;
    }
    // ...then their sums, view by view.
    // A voxel's hits in a view (more than one where it has more than kMaxHitPixels pixels there)
    // are summed as integers, exactly, and written once.
    view_sums.resize(total);
    for (int view = 0; view < num_views; ++view) {
      auto [hit, end] = hits_from(view);
      while (hit != end && hit->k < last) {
        const int k = hit->k;
        uint64_t pixels = 0, sum[3] = {0, 0, 0}, sum_squares[3] = {0, 0, 0};
        for (; hit != end && hit->k == k; ++hit) {
          pixels += hit->count;
          for (int c = 0; c < 3; ++c) {
            sum[c] += hit->sum[c];
            sum_squares[c] += hit->sum_squares[c];
          }
        }
        const int i = k - first;
        ViewColourStats& view_stats = view_sums[begin[i] + count[i]++];
        view_stats.view = view;
        view_stats.count = static_cast<int>(pixels);
        view_stats.sum = Eigen::Vector3d(static_cast<double>(sum[0]), static_cast<double>(sum[1]),
                                         static_cast<double>(sum[2]));
        view_stats.sum_squares =
            Eigen::Vector3d(static_cast<double>(sum_squares[0]),
                            static_cast<double>(sum_squares[1]),
                            static_cast<double>(sum_squares[2]));
      }
    }
    for (int k = first; k < last; ++k) {
      const int i = k - first;
      stats.assign(view_sums.begin() + begin[i], view_sums.begin() + begin[i + 1]);
      BatchEntry& entry = batch->entries[k];
      entry.num_pixels = 0;
      for (const ViewColourStats& view_stats : stats) entry.num_pixels += view_stats.count;
      entry.consistency = Judge(entry.voxel, stats);
      entry.carve = !entry.consistency.consistent;
      entry.kept_protected = false;
      if (entry.carve && (IsProtected(entry.voxel) || BehindKnownSurface(entry.voxel, stats))) {
        entry.carve = false;
        entry.kept_protected = true;
      }
      if (colouring) {
        // The pixels' distance to the voxel's colour, summed view by view in pixel order.
        double error = 0.0;
        for (int view = 0; view < num_views; ++view) {
          const ViewBuffers& buffers = view_buffers_[view];
          const Span& span = buffers.spans[slot][k];
          for (uint32_t p = span.begin; p < span.end; ++p) {
            error += (PixelColour(buffers.vis[slot][p]) - entry.consistency.colour).norm();
          }
        }
        entry.reprojection_error = error;
      }
    }
  };
  const int count = static_cast<int>(batch->entries.size());
  if (!colouring && !patterns_) {
    judge(0, count, 0);
    return;
  }
  const int chunks = (count + kClaimChunk - 1) / kClaimChunk;
  ClaimItems(workers_, chunks, 1, [&](int chunk, int group) {
    judge(chunk * kClaimChunk, std::min(count, (chunk + 1) * kClaimChunk), group);
  });
}

void IncrementalCarver::ReturnPendingBatch() {
  QueuePendingArrivals();
  if (!batch_found_) return;
  // The queued bits are still set: the voxels go back to the front, in their order.
  const std::vector<BatchEntry>& entries = batches_[current_].entries;
  for (auto entry = entries.rbegin(); entry != entries.rend(); ++entry) {
    queue_.push_front(entry->voxel);
  }
  batches_[current_].Clear();
  batch_found_ = false;
}

bool IncrementalCarver::StepBatch() {
  Batch& current = batches_[current_];
  if (!batch_found_) {
    FormBatch(&current);
    if (current.entries.empty()) return false;
    RunViewTask(nullptr, 0, &current, current_);
  }
  if (workers_.num_groups() > 1) {
    // The next batch's coordinates are written after the judging, and the other threads read
    // them last (see PrefetchForWriting).
    const std::vector<Eigen::Vector3i>& next_coordinates = batches_[1 - current_].coordinates;
    PrefetchForWriting(next_coordinates.data(),
                       next_coordinates.capacity() * sizeof(Eigen::Vector3i));
  }
  // Every voxel judged against the rays as they stood before any of the batch was carved.
  JudgeEntries(&current, current_, /*colouring=*/false);
  evaluated_ += static_cast<int64_t>(current.entries.size());
  batch_carved_.clear();
  for (int k = 0; k < static_cast<int>(current.entries.size()); ++k) {
    const BatchEntry& entry = current.entries[k];
    protected_kept_ += entry.kept_protected;
    if (entry.carve) batch_carved_.push_back(k);
  }
  // The voxels a carve exposes are queued as rays reach them (QueuePendingArrivals), not here.
  for (int k : batch_carved_) volume_.Carve(current.entries[k].voxel, nullptr);
  carved_ += static_cast<int64_t>(batch_carved_.size());
  // The rays that ended in the carved voxels step on (through all of them), and the next batch's
  // Vis is found after them, view by view in one task; in it the calling thread queues the
  // voxels the last task's rays reached (QueuePendingArrivals). The queue is as if they had been
  // queued before this batch was judged, as the FIFO order has it: the next batch comes from the
  // queue's front, and they go to its back (FormBatch queues them first where the queue runs
  // out); this batch's voxels keep their queued bits until then, so that they are not queued
  // again (judged with the rays as the last carve left them); a voxel carved since it was reached
  // was queued then and, taken by FormBatch, skipped (QueuePendingArrivals checks).
  const int next_slot = 1 - current_;
  Batch& next = batches_[next_slot];
  FormBatch(&next);
  if (!batch_carved_.empty() || !next.entries.empty()) {
    RunViewTask(batch_carved_.empty() ? nullptr : &current, current_,
                next.entries.empty() ? nullptr : &next, next_slot);
  } else {
    QueuePendingArrivals();
  }
  max_queue_ = std::max(max_queue_, queue_size() + next.entries.size());
  for (const BatchEntry& entry : current.entries) {
    queued_[entry.voxel >> 6] &= ~(uint64_t{1} << (entry.voxel & 63));
  }
  if (!batch_carved_.empty()) {
    pending_slot_ = current_;
    pending_carved_ = batch_carved_.size();
  }
  current_ = next_slot;
  batch_found_ = !next.entries.empty();
  return true;
}


}  // namespace raycarve
