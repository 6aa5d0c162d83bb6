#include "api/explore/engine.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <map>
#include <mutex>
#include <new>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>

#include "api/bat_json.hpp"
#include "api/explore/direct_columns.hpp"
#include "api/explore/engine_internal.hpp"
#include "api/json_reader.hpp"
#include "api/memory_reserve.hpp"
#include "api/scene_json.hpp"
#include "api/trade_units.hpp"
#include "core/numerics/timing_book.hpp"
#include "core/scene/output_registry.hpp"

namespace sweetspot::api {

using Json = nlohmann::json;

namespace {

using explore_direct::CompileAccessor;
using explore_direct::DumpRow;
using explore_direct::NeedsImperial;
using explore_run::BlockCost;
using explore_run::BlockDesigns;
using explore_run::BlockResult;
using explore_run::EvaluateBlock;
using explore_run::RunPlan;
using explore_run::Worker;

// ---- RunSweep's steps -------------------------------------------------------------------------

// Step 1, the plan: which rows carry trade-unit twins, whether rows are written directly (every
// column and objective compiled to an accessor), the NDJSON keys' order, and the lean path.
RunPlan MakePlan(const Sweep& sweep, RowFormat format, const std::vector<ExploreColumn>& columns) {
  RunPlan plan;
  plan.memory_failures = MemoryFailures();
  plan.sweep = &sweep;
  plan.format = format;
  plan.columns = &columns;
  const core::Shard& shard = sweep.shard;
  const std::uint64_t total = sweep.total;
  plan.in_shard = total / shard.count + (shard.index < total % shard.count ? 1 : 0);
  // The trade-unit fields: in full rows with report_units imperial; in the JSON rows that
  // columns and objectives read when one of them names such a field (not in the SI row).
  plan.row_twins = sweep.imperial && columns.empty();
  plan.json_twins = plan.row_twins;
  if (!columns.empty()) {
    std::vector<std::string> parameter_paths;
    for (const SweepParameter& parameter : sweep.parameters)
      parameter_paths.push_back(parameter.path);
    const Json si_shape = RowShape(parameter_paths, sweep.outputs);
    for (const ExploreColumn& column : columns) {
      plan.json_twins = plan.json_twins || FindAt(si_shape, column.tokens) == nullptr;
    }
    for (const ParetoObjective& objective : sweep.objectives) {
      plan.json_twins = plan.json_twins || FindAt(si_shape, objective.tokens) == nullptr;
    }
  }
  // Direct rows: every column and objective is read from the outcome (a full row is JSON).
  if (sweep.binder && !columns.empty()) {
    plan.direct = true;
    for (const ExploreColumn& column : columns) {
      const auto a = CompileAccessor(column.tokens, sweep.parameters, sweep.outputs);
      if (!a) plan.direct = false;
      if (a) plan.column_accessors.push_back(*a);
    }
    for (const ParetoObjective& objective : sweep.objectives) {
      const auto a = CompileAccessor(objective.tokens, sweep.parameters, sweep.outputs);
      if (!a) plan.direct = false;
      if (a) plan.objective_accessors.push_back(*a);
    }
    plan.imperial = NeedsImperial(plan.column_accessors) || NeedsImperial(plan.objective_accessors);
  }
  if (plan.direct && format == RowFormat::kNdjson) {
    // A JSON object's keys are in std::map order, each once (the last value set wins; a path's
    // values are the same).
    std::vector<std::size_t> order(columns.size());
    for (std::size_t c = 0; c < order.size(); ++c) order[c] = c;
    std::stable_sort(order.begin(), order.end(), [&columns](std::size_t a, std::size_t b) {
      return columns[a].path < columns[b].path;
    });
    for (const std::size_t c : order) {
      if (!plan.ndjson_keys.empty() &&
          columns[plan.ndjson_keys.back().first].path == columns[c].path) {
        continue;
      }
      plan.ndjson_keys.emplace_back(c, DumpRow(Json(columns[c].path)) + ":");
    }
  }
  // The lean path reads no collision efficiency (the outputs do not ask for it) and no centre
  // of percussion (an output it does not take).
  plan.lean = (plan.direct || (sweep.binder && columns.empty() && format != RowFormat::kCsv)) &&
              !sweep.outputs.collision_efficiency &&
              core::ClosedFormDesigns::Applies(sweep.options, sweep.binder->base_scene());
  return plan;
}

// Step 2, the tally: takes the finished blocks in design order, hands their rows on, counts
// them and keeps the Pareto front as it grows.
class SweepTally {
 public:
  SweepTally(const Sweep& sweep, const RunPlan& plan, core::Progress* progress,
             const std::function<bool(BlockRows&)>& emit, SweepOutcome* outcome)
      : sweep_(sweep), plan_(plan), progress_(progress), emit_(emit), outcome_(outcome) {
    for (const auto& o : sweep.objectives) senses_.push_back(o.sense);
    cut_at_ = std::max<std::size_t>(1, sweep.pareto_cut_min);
  }

  // Takes a finished block: false when the sweep ends here (cancelled or stopped).
  bool Take(BlockResult& block) {
    if (block.cancelled || core::IsCancelled(progress_)) {
      outcome_->cancelled = true;
      outcome_->message =
          "the sweep was cancelled after " + std::to_string(evaluated) + " designs";
      return false;
    }
    failed += block.failed;
    beyond_tip += block.beyond_tip;
    before_knob += block.before_knob;
    for (auto& v : block.objective_values) objective_values_.push_back(std::move(v));
    indices.insert(indices.end(), block.indices.begin(), block.indices.end());
    if (!senses_.empty() && objective_values_.size() >= cut_at_) {
      CutToFront();
      cut_at_ = std::max(sweep_.pareto_cut_min, 8 * objective_values_.size());
    }
    if (!emit_(block.rows)) {
      outcome_->stopped = true;
      return false;
    }
    evaluated += block.rows.count;
    if (progress_ != nullptr && plan_.in_shard > 0) {
      progress_->Report(static_cast<double>(evaluated) / static_cast<double>(plan_.in_shard));
    }
    return true;
  }

  // The Pareto front kept as it grows: a design dominated by the designs so far is dominated
  // in the whole sweep, and a design on the whole front is on the front of any set holding it,
  // so the values are cut to their front whenever they have grown 8-fold since the last cut
  // (memory of the order of the front, not of the sweep; the same front, in design order). A
  // cut costs O(values x front), so cutting more often would cost more time than one cut at
  // the end.
  void CutToFront() {
    std::vector<std::vector<double>> kept_values;
    std::vector<std::uint64_t> kept_indices;
    for (const std::size_t k : core::ParetoFront(objective_values_, senses_)) {
      kept_values.push_back(std::move(objective_values_[k]));
      kept_indices.push_back(indices[k]);
    }
    objective_values_ = std::move(kept_values);
    indices = std::move(kept_indices);
  }

  std::uint64_t evaluated = 0, failed = 0, beyond_tip = 0, before_knob = 0;
  std::vector<std::uint64_t> indices;  // the designs whose objectives are kept (the front)

 private:
  const Sweep& sweep_;
  const RunPlan& plan_;
  core::Progress* progress_;
  const std::function<bool(BlockRows&)>& emit_;
  SweepOutcome* outcome_;
  std::vector<std::vector<double>> objective_values_;
  std::vector<core::Sense> senses_;
  std::size_t cut_at_ = 1;
};

// Step 3a: the shard's `n` designs in blocks on this thread alone. False when the tally ended
// the sweep (cancelled or stopped). An exception goes to the caller.
bool RunOnThisThread(const RunPlan& plan, std::uint64_t n, core::Progress* progress,
                     SweepTally* tally) {
  Worker worker;
  BlockCost cost;
  for (std::uint64_t k = 0; k < n;) {
    BlockResult block;
    const std::uint64_t count = std::min(n - k, BlockDesigns(cost));
    EvaluateBlock(plan, k, count, progress, &worker, &block, &cost);
    k += count;
    if (!tally->Take(block)) return false;
  }
  return true;
}

// Step 3b: the shard's `n` designs on this thread and `helpers` more from sweep.budget (given
// back at the end). Workers (this thread among them) take the next designs as a block; this
// thread hands the blocks on in design order. At most `window` blocks are finished or being
// evaluated beyond the one handed on next. False when the tally ended the sweep; the first
// exception of any thread in *failure (every thread joined).
bool RunWithHelpers(const RunPlan& plan, std::uint64_t n, int helpers, core::Progress* progress,
                    SweepTally* tally, std::exception_ptr* failure_out) {
  const Sweep& sweep = *plan.sweep;
  std::mutex mutex;
  std::condition_variable ready, room;
  std::map<std::uint64_t, BlockResult> done;  // by first design
  std::uint64_t next = 0;                     // the first design not taken yet
  std::uint64_t in_flight = 0;                // blocks being evaluated
  BlockCost cost;                             // what a design of the last block cost
  bool stop = false;
  std::exception_ptr failure;  // the first exception of any thread (then stop)
  const std::uint64_t window = 4 * static_cast<std::uint64_t>(helpers + 1);
  const auto has_room = [&] { return next < n && done.size() + in_flight < window; };
  // Takes the next block under the lock: [*first, *first + *count).
  const auto claim = [&](std::uint64_t* first, std::uint64_t* count) {
    *first = next;
    *count = std::min(n - next, BlockDesigns(cost));
    next += *count;
    ++in_flight;
  };
  // Evaluates a claimed block outside the lock, then files it under the lock.
  const auto evaluate = [&](std::unique_lock<std::mutex>& lock, std::uint64_t first,
                            std::uint64_t count, Worker* worker) {
    BlockResult block;
    BlockCost measured = cost;
    lock.unlock();
    EvaluateBlock(plan, first, count, progress, worker, &block, &measured);
    lock.lock();
    cost = measured;
    done.emplace(first, std::move(block));
    --in_flight;
  };
  // Records the first exception of any thread and stops every thread (`lock` may or may not
  // hold the mutex: an exception inside `evaluate` leaves it released).
  const auto record_failure = [&](std::unique_lock<std::mutex>& lock) {
    if (!lock.owns_lock()) lock.lock();
    if (!failure) failure = std::current_exception();
    stop = true;
    lock.unlock();
    ready.notify_all();
    room.notify_all();
  };
  const auto work = [&]() {
    std::unique_lock<std::mutex> lock(mutex, std::defer_lock);
    try {
      Worker worker;
      lock.lock();
      for (;;) {
        room.wait(lock, [&] { return stop || next >= n || has_room(); });
        if (stop || next >= n) return;
        std::uint64_t first = 0, count = 0;
        claim(&first, &count);
        evaluate(lock, first, count, &worker);
        ready.notify_all();
      }
    } catch (...) {
      record_failure(lock);
    }
  };
  std::vector<std::thread> threads;
  bool ok = true;
  try {
    threads.reserve(static_cast<std::size_t>(helpers));
    for (int t = 0; t < helpers; ++t) threads.emplace_back(work);
  } catch (...) {
    // A thread that could not start (std::system_error: no memory for its stack): the
    // threads that did start, and this one, do the work; the rest go back to the budget.
  }
  if (sweep.budget != nullptr) sweep.budget->Give(helpers - static_cast<int>(threads.size()));
  std::uint64_t handed = 0;  // the first design not handed on yet
  {
    std::unique_lock<std::mutex> lock(mutex, std::defer_lock);
    try {
      Worker own_worker;
      while (ok && handed < n) {
        BlockResult block;
        lock.lock();
        ready.wait(lock, [&] { return failure || done.count(handed) > 0 || has_room(); });
        if (failure) {
          lock.unlock();
          break;
        }
        if (done.count(handed) == 0) {
          // The next block is not finished and there is room: this thread evaluates one too.
          std::uint64_t first = 0, count = 0;
          claim(&first, &count);
          evaluate(lock, first, count, &own_worker);
          lock.unlock();
          continue;
        }
        block = std::move(done[handed]);
        done.erase(handed);
        // A cancelled block is short: what follows it is never handed on.
        handed += block.cancelled ? n : block.rows.count;
        lock.unlock();
        room.notify_all();
        ok = tally->Take(block);
      }
    } catch (...) {
      record_failure(lock);
    }
  }
  {
    std::lock_guard<std::mutex> lock(mutex);
    stop = true;
  }
  room.notify_all();
  for (std::thread& t : threads) t.join();
  if (sweep.budget != nullptr) sweep.budget->Give(static_cast<int>(threads.size()));
  *failure_out = failure;
  return ok;
}

// Step 4a: the outcome of a sweep an exception ended after `evaluated` designs.
SweepOutcome FailedOutcome(const std::exception_ptr& caught, std::uint64_t evaluated) {
  SweepOutcome outcome;
  outcome.failed = true;
  std::string what = "an unknown exception";
  try {
    std::rethrow_exception(caught);
  } catch (const std::bad_alloc&) {
    what = "out of memory (std::bad_alloc)";
  } catch (const std::system_error& e) {
    what = std::string("a system error (") + e.code().message() + ")";
  } catch (...) {
  }
  outcome.message = "the sweep failed after " + std::to_string(evaluated) + " designs: " + what;
  return outcome;
}

// Step 4b: the summary of a sweep that ran to its end.
Json SweepSummary(const Sweep& sweep, SweepTally* tally) {
  const core::Shard& shard = sweep.shard;
  Json summary{{"designs_total", sweep.total},
               {"designs_in_shard", tally->evaluated},
               {"failed", tally->failed},
               {"sampling", core::SamplingMethodName(sweep.plan.method)},
               {"seed", sweep.plan.seed},
               {"shard", {{"index", shard.index}, {"count", shard.count}}},
               {"timing_s", core::SecondsSince(sweep.start)}};
  if (!sweep.objectives.empty()) {
    tally->CutToFront();
    Json front = tally->indices;
    summary["pareto_front"] = std::move(front);
    summary["pareto_objectives"] = ObjectivesToJson(sweep.objectives);  // for explore-merge
    summary["pareto_scope"] = "the rows of this response (this shard)";
  }
  if (std::any_of(sweep.outputs.scene.begin(), sweep.outputs.scene.end(), [](auto o) {
        return core::SceneOutputDeclaration(o).uses_exit_model;
      })) {
    summary["exit_speed_model"] = sweep.exit_speed_model;
    summary["model_reason"] = sweep.model_reason;
  }
  AddEndPlacements(tally->beyond_tip, tally->before_knob, &summary);
  if (sweep.imperial) summary["report_units"] = "imperial";  // explore-merge keeps it
  summary["provenance"] = sweep.provenance;
  return summary;
}

}  // namespace

// ---- RunSweep --------------------------------------------------------------------------------

SweepOutcome RunSweep(const Sweep& sweep, RowFormat format,
                      const std::vector<ExploreColumn>& columns, core::Progress* progress,
                      const std::function<bool(BlockRows&)>& emit) {
  SweepOutcome outcome;
  if (!RestoreMemoryReserve()) {
    // An earlier allocation failed and its reserve cannot be taken back yet: a sweep now could
    // fail where nothing is left to unwind with (api/memory_reserve.hpp).
    outcome.failed = true;
    outcome.message =
        "the server is low on memory (an allocation failed earlier and the memory "
        "it kept back cannot be taken again yet)";
    return outcome;
  }
  const RunPlan plan = MakePlan(sweep, format, columns);
  SweepTally tally(sweep, plan, progress, emit, &outcome);
  // Threads beyond this one come from the budget, without waiting for it.
  const std::uint64_t n = plan.in_shard;
  int helpers = static_cast<int>(std::min<std::uint64_t>(
      static_cast<std::uint64_t>(std::max(1, sweep.threads) - 1), n > 0 ? n - 1 : 0));
  if (helpers > 0 && sweep.budget != nullptr) helpers = sweep.budget->TryTake(helpers);
  // An exception (std::bad_alloc) in any thread of the sweep ends it as a failure: in a
  // helper std::thread it would otherwise reach std::terminate and end the process.
  if (helpers <= 0) {
    try {
      if (!RunOnThisThread(plan, n, progress, &tally)) return outcome;
    } catch (...) {
      return FailedOutcome(std::current_exception(), tally.evaluated);
    }
  } else {
    std::exception_ptr failure;
    const bool ok = RunWithHelpers(plan, n, helpers, progress, &tally, &failure);
    if (failure) return FailedOutcome(failure, tally.evaluated);
    if (!ok) return outcome;
  }
  outcome.summary = SweepSummary(sweep, &tally);
  return outcome;
}

}  // namespace sweetspot::api
