// The MPI implementation of Collective (compiled only when CMake finds MPI).
#include <mpi.h>

#include <stdexcept>
#include <vector>

#include "lrcal/study/collective.h"

namespace lrcal {

namespace {

class MpiCollective : public Collective {
 public:
  MpiCollective(int* argc, char*** argv) {
    int provided = 0;
    // Worker threads never call MPI; only the main thread does.
    MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  ~MpiCollective() override { MPI_Finalize(); }
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void Barrier() override { MPI_Barrier(MPI_COMM_WORLD); }
  std::string Broadcast(const std::string& text) override { return BroadcastFrom(0, text); }
  std::string FirstNonEmpty(const std::string& text) override {
    int mine = text.empty() ? size_ : rank_, first = size_;
    MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return first == size_ ? "" : BroadcastFrom(first, text);
  }
  void Send(int to, int tag, long long value) override {
    MPI_Send(&value, 1, MPI_LONG_LONG, to, tag, MPI_COMM_WORLD);
  }
  bool TryReceive(int* from, int* tag, long long* value) override {
    int flag = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status);
    if (!flag) return false;
    MPI_Recv(value, 1, MPI_LONG_LONG, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
             MPI_STATUS_IGNORE);
    *from = status.MPI_SOURCE;
    *tag = status.MPI_TAG;
    return true;
  }
  long long Receive(int from, int tag) override {
    long long value = 0;
    MPI_Recv(&value, 1, MPI_LONG_LONG, from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return value;
  }
  long long SumAll(long long value) override {
    long long sum = 0;
    MPI_Allreduce(&value, &sum, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    return sum;
  }

 private:
  // `root`'s text on every rank: its length, then its bytes.
  std::string BroadcastFrom(int root, const std::string& text) {
    long long length = static_cast<long long>(text.size());
    MPI_Bcast(&length, 1, MPI_LONG_LONG, root, MPI_COMM_WORLD);
    std::vector<char> buffer(text.begin(), text.end());
    buffer.resize(static_cast<std::size_t>(length));
    if (length > 0)
      MPI_Bcast(buffer.data(), static_cast<int>(length), MPI_CHAR, root, MPI_COMM_WORLD);
    return std::string(buffer.begin(), buffer.end());
  }

  int rank_ = 0, size_ = 1;
};

}  // namespace

bool BuiltWithMpi() { return true; }

std::unique_ptr<Collective> MpiWorld(int* argc, char*** argv) {
  return std::make_unique<MpiCollective>(argc, argv);
}

}  // namespace lrcal
