// The trial store opened by several connections at once: a run creating its store while
// `lrcal status`, a report or a test opens the same file.
#include "lrcal/study/trial_store.h"

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "test_util.h"

namespace lrcal {
namespace {

// Connections opening one new store at the same instant, per round; and rounds. Before the switch
// to WAL and the schema waited for each other's locks, about 6 % of such openings failed with
// "database is locked" on a 2-core machine, so these rounds all passing by chance is unlikely
// (0.94^180 < 1e-4).
constexpr int kConnectionsAtOnce = 3;
constexpr int kRounds = 60;

TEST(TrialStore, ConnectionsOpeningANewStoreAtOnceAllSucceed) {
  const std::string dir = testing::TempDir("store_open_race");
  std::vector<std::string> failures;
  std::mutex failures_mutex;
  for (int round = 0; round < kRounds; ++round) {
    const std::string path = dir + "/store" + std::to_string(round) + ".sqlite";
    std::atomic<int> waiting{kConnectionsAtOnce};
    std::vector<std::thread> openers;
    for (int k = 0; k < kConnectionsAtOnce; ++k) {
      openers.emplace_back([&] {
        // Start together: the race is in the first milliseconds of the file's life.
        --waiting;
        while (waiting.load() > 0) std::this_thread::yield();
        try {
          TrialStore store(path);
          EXPECT_EQ(store.CountTrials(), 0);
          EXPECT_TRUE(store.CellIds().empty());
        } catch (const std::exception& e) {
          const std::lock_guard<std::mutex> lock(failures_mutex);
          failures.push_back(e.what());
        }
      });
    }
    for (auto& t : openers) t.join();
  }
  EXPECT_TRUE(failures.empty()) << failures.size() << " of " << kRounds * kConnectionsAtOnce
                                << " openings failed; the first: "
                                << (failures.empty() ? "" : failures.front());
}

TEST(TrialStore, WhatOneConnectionWritesAnotherOpenedAtTheSameTimeReads) {
  const std::string path = testing::TempDir("store_two_connections") + "/store.sqlite";
  TrialStore writer(path);
  TrialStore reader(path);
  writer.SetMeta("study", "paper");
  EXPECT_EQ(reader.GetMeta("study"), "paper");
  StoredCell cell;
  cell.id = "c0";
  cell.label = "first";
  cell.settings = "{}";
  writer.PutCell(cell);
  ASSERT_EQ(reader.CellIds().size(), 1U);
  EXPECT_EQ(reader.CellIds()[0], "c0");
}

}  // namespace
}  // namespace lrcal
