// Where a sweep's tasks run: on threads of this process, or on the ranks of an MPI job (one coordinator, the rest workers).
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace tippe {

// Every process of a farm runs the same code (SPMD): the coordinator owns the output directory
// and receives every result; workers only run tasks. In one process the coordinator is the only
// process and its threads are the workers.
class TaskFarm {
 public:
  using Task = std::function<std::string(size_t)>;            // runs anywhere; its result travels back
  using Done = std::function<void(size_t, std::string&&)>;    // on the coordinator, one call at a time
  using Started = std::function<void(size_t)>;                // on the coordinator, as a task is handed out
  using Idle = std::function<void()>;                         // on the coordinator, a few times a second

  virtual ~TaskFarm() = default;
  virtual bool coordinator() const = 0;
  // How many tasks run at once.
  virtual int workers() const = 0;
  // Whether other processes take part (a broadcast then carries bytes).
  virtual bool distributed() const = 0;
  // The coordinator's `bytes` replace every other process's.
  virtual void broadcast(std::string& bytes) = 0;
  // On the coordinator, every process's `token`, by rank (its own first); elsewhere empty.
  virtual std::vector<std::string> gather(const std::string& token) = 0;
  // Runs task(k) exactly once for every k in [0, n), handing tasks out in increasing k as
  // workers come free. Every process returns, or throws, alike: an exception in a task or in
  // `done` stops the handing out, the tasks already running finish and reach `done`, then the
  // first exception is rethrown (in one process) or every process throws FarmError with its text.
  virtual void run(size_t n, const Task& task, const Done& done, const Started& started = {},
                   const Idle& idle = {}) = 0;
};

// What run() throws on every process when a task or `done` failed somewhere.
class FarmError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The first error of any process, for every process: each passes its own ("" for none); the
// coordinator's comes first, then the lowest rank's, prefixed "rank R: ". "" when none failed.
std::string first_error(TaskFarm& farm, const std::string& error);

// `jobs` threads of this process.
std::unique_ptr<TaskFarm> make_thread_farm(int jobs);

// Runs fn(0..n-1) on `jobs` threads; the first exception is rethrown after every thread ends;
// `idle` is called five times a second on the calling thread while they run.
void parallel_for(size_t n, int jobs, const std::function<void(size_t)>& fn, const std::function<void()>& idle = {});

}  // namespace tippe
