#include "lrcal/study/collective.h"

#include <cstdlib>
#include <stdexcept>

namespace lrcal {

namespace {

class Single : public Collective {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void Barrier() override {}
  std::string Broadcast(const std::string& text) override { return text; }
  long long SumAll(long long value) override { return value; }
  std::string FirstNonEmpty(const std::string& text) override { return text; }
  void Send(int, int, long long) override { throw std::logic_error("no other rank"); }
  bool TryReceive(int*, int*, long long*) override { return false; }
  long long Receive(int, int) override { throw std::logic_error("no other rank"); }
};

int EnvInt(const char* name) {
  const char* v = std::getenv(name);
  return v ? std::atoi(v) : 0;
}

}  // namespace

std::unique_ptr<Collective> SingleProcess() { return std::make_unique<Single>(); }

bool LaunchedUnderMpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS"})
    if (EnvInt(name) > 1) return true;
  return false;
}

#ifndef LRCAL_WITH_MPI
bool BuiltWithMpi() { return false; }
std::unique_ptr<Collective> MpiWorld(int*, char***) {
  throw std::runtime_error("this lrcal was built without MPI");
}
#endif

}  // namespace lrcal
