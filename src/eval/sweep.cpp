#include "eval/sweep.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.hpp"
#include "core/text.hpp"

namespace roiflow::eval {
namespace {

bool is_integer_param(SweepParam param) {
  return param == SweepParam::Patch || param == SweepParam::Iterations ||
         param == SweepParam::Levels;
}

std::vector<double> range(int first, int last) {
  std::vector<double> values;
  for (int v = first; v <= last; ++v)
    values.push_back(v);
  return values;
}

std::vector<double> with_base(std::vector<double> values, double base) {
  if (std::find(values.begin(), values.end(), base) == values.end()) {
    values.push_back(base);
    std::sort(values.begin(), values.end());
  }
  return values;
}

}  // namespace

const char* to_string(SweepParam param) {
  switch (param) {
    case SweepParam::Patch:
      return "patch";
    case SweepParam::Iterations:
      return "iterations";
    case SweepParam::Levels:
      return "levels";
    case SweepParam::Sigma:
      return "sigma";
    case SweepParam::Lambda:
      return "lambda";
  }
  return "?";
}

SweepParam sweep_param_from_string(std::string_view name) {
  for (SweepParam p : all_sweep_params()) {
    if (name == to_string(p)) return p;
  }
  throw Error("unknown sweep parameter '" + std::string(name) +
              "' (expected patch, iterations, levels, sigma or lambda)");
}

std::vector<SweepParam> all_sweep_params() {
  return {SweepParam::Patch, SweepParam::Iterations, SweepParam::Levels, SweepParam::Sigma,
          SweepParam::Lambda};
}

std::vector<double> default_sweep_values(SweepParam param, const flow::LkParams& base) {
  switch (param) {
    case SweepParam::Patch:
      return range(3, 31);
    case SweepParam::Iterations:
      return range(1, 10);
    case SweepParam::Levels:
      return range(1, flow::kMaxLevels);
    case SweepParam::Sigma:
      return with_base({0.0, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0}, base.sigma);
    case SweepParam::Lambda:
      return with_base({1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2}, base.lambda);
  }
  return {};
}

flow::LkParams with_value(const flow::LkParams& base, SweepParam param, double value) {
  const std::string name = std::string(to_string(param)) + " " + number_text(value);
  if (!std::isfinite(value)) throw Error(name + ": not a finite number");
  if (is_integer_param(param) && (value != std::round(value) || std::abs(value) > 1e6)) {
    throw Error(name + ": " + to_string(param) + " takes whole numbers");
  }
  flow::LkParams p = base;
  switch (param) {
    case SweepParam::Patch:
      p.patch = static_cast<int>(value);
      break;
    case SweepParam::Iterations:
      p.iterations = static_cast<int>(value);
      break;
    case SweepParam::Levels:
      p.levels = static_cast<int>(value);
      break;
    case SweepParam::Sigma:
      p.sigma = value;
      break;
    case SweepParam::Lambda:
      p.lambda = value;
      break;
  }
  try {
    p.validate();
  } catch (const Error& e) {
    throw Error(name + ": " + e.what());
  }
  return p;
}

std::vector<SweepRow> sweep(const std::vector<EvalPair>& pairs, const flow::LkParams& base,
                            SweepParam param, const std::vector<double>& values,
                            const Executor* executor, const SweepProgress& progress, int repeats) {
  if (pairs.empty()) throw Error("sweep of " + std::string(to_string(param)) + ": no pair");
  if (values.empty()) throw Error("sweep of " + std::string(to_string(param)) + ": no value");
  if (repeats < 1 || repeats > 100) {
    throw Error("sweep repeats must be in 1..100, got " + std::to_string(repeats));
  }
  std::vector<flow::LkParams> params;
  for (double v : values)
    params.push_back(with_value(base, param, v));

  evaluate_pair(pairs.front(), params.front(), executor);

  std::vector<SweepRow> rows;
  for (std::size_t i = 0; i < values.size(); ++i) {
    std::vector<EvalRow> evaluated;
    for (const EvalPair& pair : pairs) {
      EvalRow row = evaluate_pair(pair, params[i], executor);
      for (int r = 1; r < repeats; ++r)
        row.ms = std::min(row.ms, evaluate_pair(pair, params[i], executor).ms);
      evaluated.push_back(row);
    }
    const EvalRow mean = mean_row(evaluated);
    SweepRow row;
    row.param = param;
    row.value = values[i];
    row.aae_deg = mean.errors.aae_deg;
    row.epe = mean.errors.epe;
    row.ms_per_pair = mean.ms;
    row.pairs = static_cast<int>(evaluated.size());
    rows.push_back(row);
    if (progress) progress(row, i);
  }
  return rows;
}

std::string sweep_value_text(double value) {
  if (value == std::round(value) && std::abs(value) < 1e9) {
    return std::to_string(static_cast<long long>(value));
  }
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.8g", value);
  return buffer;
}

std::string sweep_csv(const std::vector<SweepRow>& rows) {
  std::string out = "parameter,value,aae_deg,epe,ms_per_pair\n";
  for (const SweepRow& r : rows) {
    out += std::string(to_string(r.param)) + ',' + sweep_value_text(r.value) + ',' +
           fixed(r.aae_deg, 3) + ',' + fixed(r.epe, 4) + ',' + fixed(r.ms_per_pair, 2) + '\n';
  }
  return out;
}

std::vector<std::pair<SweepParam, std::vector<double>>> sweep_plan(
    const std::string& name, const std::vector<double>& values, const flow::LkParams& base) {
  if (name == "all" && !values.empty()) throw UsageError("--values needs one --param, not all");
  std::vector<std::pair<SweepParam, std::vector<double>>> plan;
  for (SweepParam p : name == "all" ? all_sweep_params()
                                    : std::vector<SweepParam>{sweep_param_from_string(name)}) {
    plan.emplace_back(p, values.empty() ? default_sweep_values(p, base) : values);
    for (double v : plan.back().second) {
      try {
        with_value(base, p, v);
      } catch (const Error& e) {
        throw UsageError(std::string("--values: ") + e.what());
      }
    }
  }
  return plan;
}

std::string sweep_progress_line(const SweepRow& r, std::size_t index, std::size_t count) {
  return fmt::format("sweep {} {} ({}/{}): AAE {:.3f} deg, EPE {:.4f} px, {:.2f} ms/pair",
                     to_string(r.param), sweep_value_text(r.value), index + 1, count, r.aae_deg,
                     r.epe, r.ms_per_pair);
}

std::string sweep_table(const std::vector<SweepRow>& rows) {
  std::string out = "parameter    value      AAE(deg)    EPE(px)  ms/pair\n";
  for (const SweepRow& r : rows) {
    out += fmt::format("{:<11} {:<9} {:>9.3f} {:>10.4f} {:>8.2f}\n", to_string(r.param),
                       sweep_value_text(r.value), r.aae_deg, r.epe, r.ms_per_pair);
  }
  return out;
}

}  // namespace roiflow::eval
