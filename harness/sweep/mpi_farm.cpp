// Tasks over MPI ranks (the MPI module): rank 0 hands out task indices one at a time as workers ask, and receives every result.
#include "harness/sweep/mpi_module.h"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <thread>
#include <vector>

namespace tippe {

namespace {

// Message tags. A worker's result doubles as its request for the next task, so each task costs
// one round trip.
enum Tag : int {
  kResult = 1,  // worker -> 0: int64 task (-1: none yet), then the result's bytes
  kError = 2,   // worker -> 0: int64 task, then the exception's text
  kTask = 3,    // 0 -> worker: int64 task
  kStop = 4,    // 0 -> worker: empty (all done) or the first error's text
  kGather = 5,  // worker -> 0: a token
};

// Chunks stay below MPI's int count.
constexpr size_t kChunk = size_t{1} << 30;

void check(int rc, const char* what) {
  if (rc != MPI_SUCCESS) {
    char text[MPI_MAX_ERROR_STRING];
    int len = 0;
    MPI_Error_string(rc, text, &len);
    throw std::runtime_error(std::string("MPI: ") + what + ": " + std::string(text, static_cast<size_t>(len)));
  }
}

void send(const std::string& bytes, int dest, int tag) {
  // One message per record or reference; only the broadcast needs chunks.
  if (bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max()))
    throw std::runtime_error("MPI: a message of " + std::to_string(bytes.size()) + " bytes is over MPI's 2 GiB");
  check(MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, dest, tag, MPI_COMM_WORLD), "send");
}

// Polls `ready` without holding a core: a reply to a worker's request comes within microseconds,
// so the first millisecond is spent probing; after that the rank naps between probes (a worker
// waiting while rank 0 prepares, or a rank sharing its core with a working one in an
// oversubscribed job, leaves the CPU to the others).
template <class Ready>
void wait_until(Ready ready) {
  const auto spin_until = std::chrono::steady_clock::now() + std::chrono::milliseconds(1);
  while (!ready())
    if (std::chrono::steady_clock::now() > spin_until) std::this_thread::sleep_for(std::chrono::microseconds(200));
}

MPI_Status wait_message(int source, int tag) {
  MPI_Status st;
  wait_until([&] {
    int flag = 0;
    check(MPI_Iprobe(source, tag, MPI_COMM_WORLD, &flag, &st), "probe");
    return flag != 0;
  });
  return st;
}

// Starts a non-blocking operation and waits for it to complete.
template <class Start>
void wait_request(Start start) {
  MPI_Request request;
  check(start(&request), "start");
  wait_until([&] {
    int flag = 0;
    check(MPI_Test(&request, &flag, MPI_STATUS_IGNORE), "test");
    return flag != 0;
  });
}

std::string receive(const MPI_Status& st) {
  int count = 0;
  check(MPI_Get_count(&st, MPI_BYTE, &count), "count");
  std::string bytes(static_cast<size_t>(count), '\0');
  check(MPI_Recv(bytes.data(), count, MPI_BYTE, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
        "receive");
  return bytes;
}

std::string with_index(int64_t k, const std::string& payload) {
  std::string m(sizeof k, '\0');
  std::memcpy(m.data(), &k, sizeof k);
  return m + payload;
}
int64_t index_of(const std::string& m) {
  int64_t k = -1;
  if (m.size() >= sizeof k) std::memcpy(&k, m.data(), sizeof k);
  return k;
}

class MpiFarm : public TaskFarm {
 public:
  MpiFarm(int rank, int size) : rank_(rank), size_(size) {}
  bool coordinator() const override { return rank_ == 0; }
  int workers() const override { return size_ - 1; }
  bool distributed() const override { return size_ > 1; }

  void broadcast(std::string& bytes) override {
    // A non-blocking collective (a tree: log2(ranks) steps, not one send per rank from rank 0),
    // waited for with naps, so that ranks waiting while rank 0 works do not spin.
    uint64_t n = bytes.size();
    wait_request([&](MPI_Request* r) { return MPI_Ibcast(&n, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD, r); });
    if (rank_ != 0) bytes.assign(n, '\0');
    for (size_t off = 0; off < n; off += kChunk) {
      const int count = static_cast<int>(std::min<size_t>(kChunk, n - off));
      wait_request([&](MPI_Request* r) {
        return MPI_Ibcast(bytes.data() + off, count, MPI_BYTE, 0, MPI_COMM_WORLD, r);
      });
    }
  }

  std::vector<std::string> gather(const std::string& token) override {
    if (rank_ != 0) {
      send(token, 0, kGather);
      return {};
    }
    std::vector<std::string> all{token};
    for (int r = 1; r < size_; ++r) all.push_back(receive(wait_message(r, kGather)));
    return all;
  }

  void run(size_t n, const Task& task, const Done& done, const Started& started, const Idle& idle) override {
    if (rank_ == 0)
      coordinate(n, done, started, idle);
    else
      work(task);
  }

 private:
  void coordinate(size_t n, const Done& done, const Started& started, const Idle& idle) {
    size_t next = 0, in_flight = 0;
    int stopped = 0;
    std::string error;
    // Workers with nothing left to do. They are stopped together once every task handed out has
    // come back and reached `done`, so that all of them learn the same outcome (an error in the
    // last `done` included) and leave run() alike.
    std::vector<int> waiting;
    auto last_idle = std::chrono::steady_clock::now() - std::chrono::seconds(1);
    while (stopped < size_ - 1) {
      MPI_Status st;
      int flag = 0;
      check(MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st), "probe");
      if (idle && std::chrono::steady_clock::now() - last_idle >= std::chrono::milliseconds(200)) {
        idle();
        last_idle = std::chrono::steady_clock::now();
      }
      if (!flag) {
        std::this_thread::sleep_for(std::chrono::microseconds(50));
        continue;
      }
      if (st.MPI_TAG != kResult && st.MPI_TAG != kError) {
        // Only a bug gets here; the job cannot go on in step, so it ends rather than hangs.
        std::fprintf(stderr, "tippe: error: internal: MPI message tag %d from rank %d\n", st.MPI_TAG, st.MPI_SOURCE);
        MPI_Abort(MPI_COMM_WORLD, 1);
      }
      const std::string m = receive(st);
      const int64_t k = index_of(m);
      if (k >= 0) --in_flight;
      if (st.MPI_TAG == kError && error.empty()) error = m.substr(sizeof k);
      // The worker gets its next task before its result is handled, so that appending the
      // record (an fsync) overlaps with the next run instead of keeping the worker waiting.
      if (error.empty() && next < n) {
        if (started) started(next);
        const int64_t t = static_cast<int64_t>(next++);
        ++in_flight;
        check(MPI_Send(&t, 1, MPI_INT64_T, st.MPI_SOURCE, kTask, MPI_COMM_WORLD), "send");
      } else {
        waiting.push_back(st.MPI_SOURCE);
      }
      if (st.MPI_TAG == kResult && k >= 0) {
        // A result that arrives after an error still reaches `done`: a finished point is kept.
        try {
          done(static_cast<size_t>(k), m.substr(sizeof k));
        } catch (const std::exception& e) {
          if (error.empty()) error = e.what();
        }
      }
      if (in_flight == 0 && (next == n || !error.empty())) {
        for (int w : waiting) send(error, w, kStop);
        stopped += static_cast<int>(waiting.size());
        waiting.clear();
      }
    }
    if (!error.empty()) throw FarmError(error);
  }

  void work(const Task& task) {
    send(with_index(-1, ""), 0, kResult);
    for (;;) {
      MPI_Status st = wait_message(0, MPI_ANY_TAG);
      if (st.MPI_TAG == kStop) {
        const std::string error = receive(st);
        if (!error.empty()) throw FarmError(error);
        return;
      }
      if (st.MPI_TAG != kTask) throw std::logic_error("MPI: unexpected message tag " + std::to_string(st.MPI_TAG));
      int64_t k = -1;
      check(MPI_Recv(&k, 1, MPI_INT64_T, 0, kTask, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "receive");
      std::string result;
      try {
        result = task(static_cast<size_t>(k));
      } catch (const std::exception& e) {
        send(with_index(k, e.what()), 0, kError);
        continue;
      }
      send(with_index(k, result), 0, kResult);
    }
  }

  int rank_, size_;
};

void init(int* rank, int* size) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) check(MPI_Init(nullptr, nullptr), "init");
  // Errors come back as codes (turned into exceptions) instead of aborting the job.
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, rank);
  MPI_Comm_size(MPI_COMM_WORLD, size);
}

void finalize() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
}

TaskFarm* make_farm(int rank, int size) { return new MpiFarm(rank, size); }

std::string library_version() {
  char text[MPI_MAX_LIBRARY_VERSION_STRING];
  int len = 0;
  MPI_Get_library_version(text, &len);
  std::string v(text, static_cast<size_t>(len));
  const size_t cut = v.find_first_of(",\n");
  return cut == std::string::npos ? v : v.substr(0, cut);
}

}  // namespace

}  // namespace tippe

extern "C" const tippe::MpiModule* tippe_mpi_module() {
  static const tippe::MpiModule module{tippe::init, tippe::finalize, tippe::make_farm, tippe::library_version};
  return &module;
}
