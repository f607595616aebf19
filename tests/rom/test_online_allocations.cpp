// Heap allocations of an online greedy query (docs/rom.md: "no step allocates
// memory inside the iterations"), counted by replacing malloc and its relatives in
// this program (operator new and Eigen both end in malloc). On hertz (12 snapshots,
// δ = 1e-8), after warm-up queries: the allocations of a query capped at k
// iterations must not grow with k, i.e. every iteration after the first allocates
// nothing. Where one does, the call stacks of its allocations are printed.
#define BOOST_TEST_MODULE rom_online_allocations
#include <boost/test/unit_test.hpp>

#include <cxxabi.h>
#include <execinfo.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "fom/problem.hpp"
#include "rom/greedy_active_set.hpp"
#include "rom/offline.hpp"
#include "rom/reduced_model.hpp"

extern "C" {
void* __libc_malloc(size_t size);
void* __libc_calloc(size_t count, size_t size);
void* __libc_realloc(void* p, size_t size);
void* __libc_memalign(size_t alignment, size_t size);
void __libc_free(void* p);
}

namespace {

constexpr int kMaxTraces = 64, kMaxFrames = 32;
std::atomic<bool> g_counting{false};
std::atomic<long> g_count{0};
std::atomic<int> g_traces{0};
void* g_frames[kMaxTraces][kMaxFrames];
int g_depth[kMaxTraces];
thread_local bool t_inside = false;  // backtrace() may allocate: no recursion

void note_allocation() {
  if (!g_counting.load(std::memory_order_relaxed) || t_inside) return;
  g_count.fetch_add(1, std::memory_order_relaxed);
  t_inside = true;
  const int i = g_traces.fetch_add(1, std::memory_order_relaxed);
  if (i < kMaxTraces) g_depth[i] = backtrace(g_frames[i], kMaxFrames);
  t_inside = false;
}

}  // namespace

extern "C" {
void* malloc(size_t size) {
  note_allocation();
  return __libc_malloc(size);
}
void* calloc(size_t count, size_t size) {
  note_allocation();
  return __libc_calloc(count, size);
}
void* realloc(void* p, size_t size) {
  note_allocation();
  return __libc_realloc(p, size);
}
void* memalign(size_t alignment, size_t size) {
  note_allocation();
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(size_t alignment, size_t size) {
  note_allocation();
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, size_t alignment, size_t size) {
  note_allocation();
  *out = __libc_memalign(alignment, size);
  return *out ? 0 : ENOMEM;
}
void free(void* p) { __libc_free(p); }
}

using namespace contactrom;

namespace {

/// Allocations made by f(), with their call stacks (the first kMaxTraces).
struct Counted {
  long count = 0;
  std::string stacks;
};

template <class F>
Counted count_allocations(F&& f) {
  g_traces = 0;
  g_count = 0;
  g_counting = true;
  f();
  g_counting = false;
  Counted c;
  c.count = g_count;
  std::ostringstream out;
  const int n = std::min<int>(g_traces, kMaxTraces);
  for (int i = 0; i < n; ++i) {
    out << "allocation " << i << ":\n";
    char** names = backtrace_symbols(g_frames[i], g_depth[i]);
    for (int f = 1; f < g_depth[i] && names; ++f) {  // frame 0 is note_allocation
      std::string line = names[f];
      const size_t open = line.find('('), plus = line.find('+', open);
      if (open != std::string::npos && plus != std::string::npos && plus > open + 1) {
        int status = 0;
        char* demangled = abi::__cxa_demangle(line.substr(open + 1, plus - open - 1).c_str(), nullptr, nullptr, &status);
        if (status == 0 && demangled) line = line.substr(0, open + 1) + demangled + line.substr(plus);
        std::free(demangled);
      }
      out << "    " << line << "\n";
      if (line.find("GreedyActiveSet::solve(") != std::string::npos) break;  // the query's own frame is enough
    }
    std::free(names);
  }
  c.stacks = out.str();
  return c;
}

struct Hertz {
  std::unique_ptr<fom::Problem> problem = fom::make_problem("hertz");
  rom::SnapshotDatabase db;
  std::unique_ptr<rom::ReducedModel> model;
  std::vector<fom::Param> params;
  Hertz() {
    rom::OfflineOptions off;
    off.threads = 1;
    db = rom::generate_snapshots(*problem, 12, off);
    rom::ReducedModelOptions options;
    options.delta = 1e-8;
    model = std::make_unique<rom::ReducedModel>(*problem, db, options);
    const std::vector<fom::Param> validation = fom::validation_set(*problem, 12);
    for (size_t i = 0; i < validation.size(); i += 8) params.push_back(validation[i]);
  }
};

const Hertz& hertz() {
  static const Hertz h;
  return h;
}

}  // namespace

BOOST_AUTO_TEST_CASE(the_counter_sees_operator_new_and_eigen) {
  void* frames[4];
  (void)backtrace(frames, 4);  // loads the unwinder before counting
  const Counted c = count_allocations([] {
    auto p = std::make_unique<int>(3);
    Eigen::VectorXd v(100);
    v.setZero();
    (void)p;
  });
  BOOST_TEST(c.count == 2);
}

BOOST_AUTO_TEST_CASE(iterations_after_the_first_allocate_nothing) {
  const Hertz& h = hertz();
  for (const auto& [label, init] : {std::pair{"default start", rom::WarmStart::Cell}, std::pair{"init=empty", rom::WarmStart::Empty}}) {
    // Caps k = 1 … 12 with the k-th iterate returned as is: the queries differ only
    // in how many iterations they run.
    for (const fom::Param& mu : h.params) {
      std::vector<long> counts;
      std::vector<std::string> stacks;
      int full = 0;
      for (int cap = 1; cap <= 12; ++cap) {
        rom::GreedyOptions options;
        options.init = init;
        options.max_iterations = cap;
        const rom::GreedyActiveSet greedy(*h.model, options);
        for (int warm = 0; warm < 2; ++warm) (void)greedy.solve(mu);  // per-thread scratch sized
        rom::OnlineResult r;
        const Counted c = count_allocations([&] { r = greedy.solve(mu); });
        counts.push_back(c.count);
        stacks.push_back(c.stacks);
        full = r.iterations;
        if (r.converged) break;
      }
      BOOST_TEST_CONTEXT(label << ", d = " << mu(0) << ", allocations by cap: " << [&] {
        std::ostringstream s;
        for (long n : counts) s << n << ' ';
        return s.str();
      }()) {
        for (size_t k = 1; k < counts.size(); ++k) {
          BOOST_TEST(counts[k] <= counts[0], "cap " << k + 1 << " of " << full << " iterations:\n" << (counts[k] > counts[0] ? stacks[k] : ""));
        }
      }
    }
  }
}
