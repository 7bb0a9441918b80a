/** @file EvaluationTable.cpp
 *  @brief Aggregation and formatting of the evaluation table (paper Fig. 5, section IV).
 */
#include "uwb/eval/EvaluationTable.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

namespace uwb {
namespace {

/// 100 (corrected / uncorrected − 1): negative = the correction reduced the error.
double changePct(double uncorrected, double corrected) {
  return uncorrected > 0.0 ? 100.0 * (corrected / uncorrected - 1.0) : 0.0;
}

struct Sums {
  double unc = 0, corr = 0, before = 0, after = 0, train = 0, cov1 = 0, cov2 = 0, nlpd = 0;
  int n = 0;
  void add(const EvaluationRun& r) {
    cov1 += r.coverage_1sigma;
    cov2 += r.coverage_2sigma;
    nlpd += r.nlpd;
    unc += r.rmse_uncorrected_m;
    corr += r.rmse_corrected_m;
    before += r.bias_rmse_before_m;
    after += r.bias_rmse_after_m;
    train += r.train_seconds;
    ++n;
  }
};

}  // namespace

std::vector<EvaluationRow> aggregateRuns(const std::vector<EvaluationRun>& runs) {
  std::vector<std::string> kernel_order;
  for (const auto& r : runs) {
    if (std::find(kernel_order.begin(), kernel_order.end(), r.kernel) == kernel_order.end()) {
      kernel_order.push_back(r.kernel);
    }
  }
  std::vector<EvaluationRow> rows;
  for (const auto& kernel : kernel_order) {
    std::set<int> inducing_counts;
    for (const auto& r : runs) {
      if (r.kernel == kernel) inducing_counts.insert(r.inducing);
    }
    for (int m : inducing_counts) {
      Sums all;
      std::map<int, Sums> per_repeat;
      std::set<std::string> flights;
      for (const auto& r : runs) {
        if (r.kernel != kernel || r.inducing != m) continue;
        all.add(r);
        per_repeat[r.repeat].add(r);
        flights.insert(r.flight);
      }
      EvaluationRow row;
      row.kernel = kernel;
      row.inducing = m;
      row.n_repeats = static_cast<int>(per_repeat.size());
      row.n_flights = static_cast<int>(flights.size());
      row.rmse_uncorrected_m = all.unc / all.n;
      row.rmse_corrected_m = all.corr / all.n;
      row.change_pct = changePct(row.rmse_uncorrected_m, row.rmse_corrected_m);
      row.change_pct_min = std::numeric_limits<double>::infinity();
      row.change_pct_max = -std::numeric_limits<double>::infinity();
      for (const auto& [repeat, s] : per_repeat) {
        const double change = changePct(s.unc / s.n, s.corr / s.n);
        row.change_pct_min = std::min(row.change_pct_min, change);
        row.change_pct_max = std::max(row.change_pct_max, change);
      }
      row.bias_rmse_before_m = all.before / all.n;
      row.bias_rmse_after_m = all.after / all.n;
      row.train_seconds = all.train / all.n;
      row.coverage_1sigma = all.cov1 / all.n;
      row.coverage_2sigma = all.cov2 / all.n;
      row.nlpd = all.nlpd / all.n;
      rows.push_back(row);
    }
  }
  return rows;
}

std::string toMarkdown(const std::vector<EvaluationRow>& rows) {
  std::string out =
      "| kernel | M | RMSE uncorrected [m] | RMSE corrected [m] | change [%] | min–max over repeats [%] | "
      "bias RMSE raw → GP [m] | bias within 1σ / 2σ [%] | NLPD [nats] | train [s] |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& r : rows) {
    out += fmt::format(
        "| {} | {} | {:.3f} | {:.3f} | {:+.1f} | {:+.1f} … {:+.1f} | {:.3f} → {:.3f} | {:.1f} / {:.1f} | {:.3f} | {:.1f} |\n",
        r.kernel, r.inducing, r.rmse_uncorrected_m, r.rmse_corrected_m, r.change_pct, r.change_pct_min,
        r.change_pct_max, r.bias_rmse_before_m, r.bias_rmse_after_m, 100.0 * r.coverage_1sigma,
        100.0 * r.coverage_2sigma, r.nlpd, r.train_seconds);
  }
  return out;
}

std::string toCsv(const std::vector<EvaluationRow>& rows) {
  std::string out =
      "kernel,inducing,n_repeats,n_flights,rmse_uncorrected_m,rmse_corrected_m,change_pct,change_pct_min,"
      "change_pct_max,bias_rmse_before_m,bias_rmse_after_m,train_seconds,coverage_1sigma,coverage_2sigma,nlpd\n";
  for (const auto& r : rows) {
    out += fmt::format("{},{},{},{},{:.6f},{:.6f},{:.4f},{:.4f},{:.4f},{:.6f},{:.6f},{:.3f},{:.4f},{:.4f},{:.4f}\n",
                       r.kernel, r.inducing, r.n_repeats, r.n_flights, r.rmse_uncorrected_m, r.rmse_corrected_m,
                       r.change_pct, r.change_pct_min, r.change_pct_max, r.bias_rmse_before_m, r.bias_rmse_after_m,
                       r.train_seconds, r.coverage_1sigma, r.coverage_2sigma, r.nlpd);
  }
  return out;
}

nlohmann::json toJson(const std::vector<EvaluationRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : rows) {
    out.push_back({{"kernel", r.kernel},
                   {"inducing", r.inducing},
                   {"n_repeats", r.n_repeats},
                   {"n_flights", r.n_flights},
                   {"rmse_uncorrected_m", r.rmse_uncorrected_m},
                   {"rmse_corrected_m", r.rmse_corrected_m},
                   {"change_pct", r.change_pct},
                   {"change_pct_min", r.change_pct_min},
                   {"change_pct_max", r.change_pct_max},
                   {"bias_rmse_before_m", r.bias_rmse_before_m},
                   {"bias_rmse_after_m", r.bias_rmse_after_m},
                   {"train_seconds", r.train_seconds},
                   {"coverage_1sigma", r.coverage_1sigma},
                   {"coverage_2sigma", r.coverage_2sigma},
                   {"nlpd", r.nlpd}});
  }
  return out;
}

std::string runsToCsv(const std::vector<EvaluationRun>& runs) {
  std::string out =
      "kernel,inducing,repeat,flight,rmse_uncorrected_m,rmse_corrected_m,bias_rmse_before_m,bias_rmse_after_m,"
      "train_seconds,coverage_1sigma,coverage_2sigma,nlpd\n";
  for (const auto& r : runs) {
    out += fmt::format("{},{},{},{},{:.6f},{:.6f},{:.6f},{:.6f},{:.3f},{:.4f},{:.4f},{:.4f}\n", r.kernel, r.inducing,
                       r.repeat, r.flight, r.rmse_uncorrected_m, r.rmse_corrected_m, r.bias_rmse_before_m,
                       r.bias_rmse_after_m, r.train_seconds, r.coverage_1sigma, r.coverage_2sigma, r.nlpd);
  }
  return out;
}

nlohmann::json runsToJson(const std::vector<EvaluationRun>& runs) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : runs) {
    out.push_back({{"kernel", r.kernel},
                   {"inducing", r.inducing},
                   {"repeat", r.repeat},
                   {"flight", r.flight},
                   {"rmse_uncorrected_m", r.rmse_uncorrected_m},
                   {"rmse_corrected_m", r.rmse_corrected_m},
                   {"change_pct", changePct(r.rmse_uncorrected_m, r.rmse_corrected_m)},
                   {"bias_rmse_before_m", r.bias_rmse_before_m},
                   {"bias_rmse_after_m", r.bias_rmse_after_m},
                   {"coverage_1sigma", r.coverage_1sigma},
                   {"coverage_2sigma", r.coverage_2sigma},
                   {"nlpd", r.nlpd},
                   {"train_seconds", r.train_seconds}});
  }
  return out;
}

std::string perFlightMarkdown(const std::vector<EvaluationRun>& runs, const std::string& kernel, int inducing) {
  std::vector<std::string> order;
  std::map<std::string, std::pair<Sums, int>> by_flight;
  for (const auto& r : runs) {
    if (r.kernel != kernel || r.inducing != inducing) continue;
    if (!by_flight.count(r.flight)) order.push_back(r.flight);
    by_flight[r.flight].first.add(r);
  }
  std::string out =
      "| flight | RMSE uncorrected [m] | RMSE corrected [m] | change [%] | bias RMSE raw → GP [m] | "
      "bias within 1σ [%] | within 2σ [%] | NLPD [nats] |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& flight : order) {
    const Sums& s = by_flight.at(flight).first;
    const double n = s.n;
    out += fmt::format("| {} | {:.3f} | {:.3f} | {:+.1f} | {:.3f} → {:.3f} | {:.1f} | {:.1f} | {:.3f} |\n", flight,
                       s.unc / n, s.corr / n, changePct(s.unc / n, s.corr / n), s.before / n, s.after / n,
                       100.0 * s.cov1 / n, 100.0 * s.cov2 / n, s.nlpd / n);
  }
  return out;
}

}  // namespace uwb
