#include "study/preparation_memo.h"

#include <algorithm>
#include <mutex>
#include <vector>

namespace lrcal {

namespace {

// Every memo that exists (function-local statics register on first use).
struct Registry {
  std::mutex mutex;
  std::vector<PreparationMemoBase*> memos;
};

Registry& Memos() {
  static Registry* registry = new Registry;  // never destroyed: memos deregister at exit
  return *registry;
}

}  // namespace

PreparationMemoBase::PreparationMemoBase() {
  Registry& r = Memos();
  const std::lock_guard<std::mutex> lock(r.mutex);
  r.memos.push_back(this);
}

PreparationMemoBase::~PreparationMemoBase() {
  Registry& r = Memos();
  const std::lock_guard<std::mutex> lock(r.mutex);
  r.memos.erase(std::remove(r.memos.begin(), r.memos.end(), this), r.memos.end());
}

void ClearPreparationMemos() {
  Registry& r = Memos();
  const std::lock_guard<std::mutex> lock(r.mutex);
  for (PreparationMemoBase* memo : r.memos) memo->Clear();
}

}  // namespace lrcal
