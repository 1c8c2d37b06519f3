#include "lrcal/study/work_source.h"

#include <algorithm>

namespace lrcal {

MissingTrials::MissingTrials(const DoneSet* done, long long trials, int shard_index,
                             int shard_count, std::vector<TrialRange> ranges)
    : done_(done),
      ranges_(std::move(ranges)),
      shard_index_(shard_index),
      shard_count_(shard_count) {
  if (ranges_.empty()) ranges_.assign(done->size(), TrialRange{0, trials});
  for (auto& [first, end] : ranges_) {
    first = std::clamp<long long>(first, 0, trials);
    end = std::clamp<long long>(end, first, trials);
  }
}

bool MissingTrials::Next(TrialId* id) {
  while (cell_ < ranges_.size()) {
    const auto [first, end] = ranges_[cell_];
    t_ = std::max(t_, first);
    if (t_ >= end) {
      ++cell_;
      t_ = 0;
      continue;
    }
    const long long t = t_++;
    if (t % shard_count_ != shard_index_ || (*done_)[cell_][t]) continue;
    ++seen_;
    *id = {static_cast<int>(cell_), t};
    return true;
  }
  return false;
}

long long MissingTrials::Count() const {
  long long n = 0;
  for (std::size_t c = 0; c < ranges_.size(); ++c)
    for (long long t = ranges_[c].first; t < ranges_[c].second; ++t)
      n += t % shard_count_ == shard_index_ && !(*done_)[c][t];
  return n;
}

namespace {

// What both schedules share: this process's share of the trials and the count handed out so
// far, under the mutex that also guards each schedule's own cursor.
class CountingWorkSource : public WorkSource {
 public:
  long long claimed() const override {
    std::lock_guard<std::mutex> g(mutex_);
    return claimed_;
  }
  bool Exhausted() const override {
    std::lock_guard<std::mutex> g(mutex_);
    return claimed_ >= share_;
  }
  long long share() const override { return share_; }

 protected:
  mutable std::mutex mutex_;
  long long share_ = 0, claimed_ = 0;  // claimed_ under mutex_; share_ fixed after construction
};

// The static schedule's dealing: the missing trials, in canonical order, in blocks of `block`,
// the blocks to the ranks in turn.
struct Dealing {
  long long count;  // missing trials
  long long block;
  int ranks;
  Dealing(long long num_missing, int num_ranks)
      : count(num_missing),
        block(std::max<long long>(1, (count + kStaticBlocksPerRank * num_ranks - 1) /
                                         (kStaticBlocksPerRank * num_ranks))),
        ranks(num_ranks) {}
  // The rank of the s-th missing trial (from 0).
  int RankOf(long long s) const { return static_cast<int>((s / block) % ranks); }
  // How many of the missing trials go to `rank`.
  long long Share(int rank) const {
    const long long cycle = block * ranks;
    const long long rest = count % cycle - rank * block;
    return count / cycle * block + std::clamp<long long>(rest, 0, block);
  }
};

// The missing trials dealt to the ranks in blocks (Dealing); max_new_trials limits this process.
class StaticSchedule : public CountingWorkSource {
 public:
  StaticSchedule(MissingTrials missing, int rank, int ranks, long long max_new)
      : missing_(std::move(missing)), rank_(rank), dealing_(missing_.Count(), ranks) {
    share_ = dealing_.Share(rank);
    if (max_new > 0) share_ = std::min(share_, max_new);
  }
  void Claim(int max, std::vector<TrialId>* out) override {
    out->clear();
    std::lock_guard<std::mutex> g(mutex_);
    TrialId id;
    while (static_cast<int>(out->size()) < max && claimed_ < share_) {
      bool found = false;
      while (missing_.Next(&id))
        if (dealing_.RankOf(missing_.seen() - 1) == rank_) {
          found = true;
          break;
        }
      if (!found) break;
      out->push_back(id);
      ++claimed_;
    }
  }
  bool Pump(bool, bool workers_done) override { return workers_done; }

 private:
  MissingTrials missing_;
  int rank_;
  Dealing dealing_;
};

// Rank 0 hands out chunks of kChunk missing trials, numbered in canonical order; each rank's
// chunks arrive in increasing order, so its cursor only moves forward. Only the main thread
// talks to other ranks (Pump); workers wait for chunks under the mutex.
class DynamicSchedule : public CountingWorkSource {
 public:
  static constexpr long long kChunk = 64;
  enum : int { kTagRequest = 1, kTagChunk = 2, kTagDone = 3 };

  DynamicSchedule(MissingTrials missing, Collective* collective, long long max_new)
      : missing_(std::move(missing)), collective_(collective) {
    count_ = missing_.Count();
    num_chunks_ = (count_ + kChunk - 1) / kChunk;
    share_ = count_;  // bounded by the chunks this rank receives
    if (max_new > 0) share_ = std::min(share_, max_new);
  }

  void Claim(int max, std::vector<TrialId>* out) override {
    out->clear();
    std::unique_lock<std::mutex> g(mutex_);
    TrialId id;
    while (static_cast<int>(out->size()) < max && claimed_ < share_) {
      if (chunk_left_ == 0) {
        if (!out->empty()) break;  // hand out what we have; wait for more later
        chunk_cv_.wait(g, [&] { return !chunks_.empty() || no_more_chunks_; });
        if (chunks_.empty()) break;
        const long long first = chunks_.front() * kChunk;
        chunks_.pop_front();
        while (missing_.seen() < first && missing_.Next(&id)) {
        }
        chunk_left_ = std::min(kChunk, count_ - first);
      }
      if (!missing_.Next(&id)) break;
      --chunk_left_;
      out->push_back(id);
      ++claimed_;
    }
  }

  bool Pump(bool stopping, bool workers_done) override {
    const bool root = collective_->rank() == 0;
    if (root) Serve(stopping);
    Supply(stopping, root);
    if (!workers_done) return false;
    if (!root) {
      // Tell rank 0 this rank asks for nothing more (unless it was told so already).
      if (!requested_done_) collective_->Send(0, kTagDone, 0);
      return true;
    }
    return released_ >= collective_->size() - 1;  // rank 0 serves until every rank is released
  }

 private:
  // Rank 0: answers the other ranks' requests.
  void Serve(bool stopping) {
    int from, tag;
    long long value;
    while (collective_->TryReceive(&from, &tag, &value)) {
      if (tag == kTagDone) {
        ++released_;
      } else if (tag == kTagRequest) {
        const long long id = !stopping && next_chunk_ < num_chunks_ ? next_chunk_++ : -1;
        if (id < 0) ++released_;
        collective_->Send(from, kTagChunk, id);
      }
    }
  }
  // Keeps up to two chunks ready for this rank's workers.
  void Supply(bool stopping, bool root) {
    std::lock_guard<std::mutex> g(mutex_);
    if (no_more_chunks_ || chunks_.size() >= 2) return;
    if (stopping) {
      no_more_chunks_ = true;
    } else if (root) {
      if (next_chunk_ < num_chunks_)
        chunks_.push_back(next_chunk_++);
      else
        no_more_chunks_ = true;
    } else {
      collective_->Send(0, kTagRequest, 0);
      const long long id = collective_->Receive(0, kTagChunk);
      if (id < 0) {
        no_more_chunks_ = true;
        requested_done_ = true;
      } else {
        chunks_.push_back(id);
      }
    }
    chunk_cv_.notify_all();
  }

  std::condition_variable chunk_cv_;
  MissingTrials missing_;
  Collective* collective_;
  long long count_ = 0, num_chunks_ = 0;
  std::deque<long long> chunks_;  // chunk ids received, not started
  bool no_more_chunks_ = false;
  long long chunk_left_ = 0;  // trials left in the chunk being handed out
  // Main thread only.
  long long next_chunk_ = 0;     // rank 0: the next chunk to hand out
  int released_ = 0;             // rank 0: ranks told "no more" or that said they stopped
  bool requested_done_ = false;  // this rank was told "no more"
};

}  // namespace

StaticScheduleCells CellsOfStaticSchedule(MissingTrials missing, std::size_t num_cells, int rank,
                                          int ranks, long long max_new_trials) {
  StaticScheduleCells cells{std::vector<bool>(num_cells), std::vector<bool>(num_cells)};
  const Dealing dealing(missing.Count(), ranks);
  std::vector<long long> dealt(static_cast<std::size_t>(ranks));
  TrialId id;
  while (missing.Next(&id)) {
    const int r = dealing.RankOf(missing.seen() - 1);
    long long& n = dealt[static_cast<std::size_t>(r)];
    if (max_new_trials > 0 && n >= max_new_trials) continue;
    ++n;
    const auto c = static_cast<std::size_t>(id.first);
    cells.anyone[c] = true;
    if (r == rank) cells.mine[c] = true;
  }
  return cells;
}

std::unique_ptr<WorkSource> MakeStaticSchedule(MissingTrials missing, int rank, int ranks,
                                               long long max_new_trials) {
  return std::make_unique<StaticSchedule>(std::move(missing), rank, ranks, max_new_trials);
}

std::unique_ptr<WorkSource> MakeDynamicSchedule(MissingTrials missing, Collective* collective,
                                                long long max_new_trials) {
  return std::make_unique<DynamicSchedule>(std::move(missing), collective, max_new_trials);
}

}  // namespace lrcal
