// The few collective operations the Monte-Carlo runner needs across processes, so that
// monte_carlo.cc does not depend on MPI: one process (the default), or the ranks of an MPI job
// (`mpirun -np P lrcal run ...`, when lrcal is built with MPI).
#pragma once

#include <memory>
#include <string>

namespace lrcal {

class Collective {
 public:
  virtual ~Collective() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// Every rank waits for all the others.
  virtual void Barrier() = 0;
  /// Rank 0's `text` on every rank.
  virtual std::string Broadcast(const std::string& text) = 0;
  /// The sum over ranks of `value`, on every rank.
  virtual long long SumAll(long long value) = 0;
  /// The `text` of the lowest rank whose text is not empty, on every rank ("" when all are).
  virtual std::string FirstNonEmpty(const std::string& text) = 0;
  /// Point-to-point messages of one number (the dynamic work queue).
  virtual void Send(int to, int tag, long long value) = 0;
  /// A waiting message from any rank, if there is one (does not block).
  virtual bool TryReceive(int* from, int* tag, long long* value) = 0;
  /// Waits for a message with `tag` from rank `from`.
  virtual long long Receive(int from, int tag) = 0;
};

/// A single process: rank 0 of 1.
std::unique_ptr<Collective> SingleProcess();

/// True if this process was started by an MPI launcher with more than one rank (OpenMPI,
/// MPICH/PMI or PMIx environment variables).
bool LaunchedUnderMpi();

/// True if this lrcal was built with MPI support.
bool BuiltWithMpi();

/// The MPI world (initialises MPI; finalised when the object is destroyed). Throws if lrcal was
/// built without MPI.
std::unique_ptr<Collective> MpiWorld(int* argc, char*** argv);

}  // namespace lrcal
