/** @file bind_gp_train.cpp
 *  @brief Python bindings of uwb/gp/SvgpTrainer.h: k-means++ inducing points, SVGP initialisation and training.
 */
#include "bindings.h"
#include "uwb/gp/SvgpTrainer.h"

namespace uwb::python {
namespace {

using gp::Svgp;
using gp::SvgpTrainParams;

MatX matX(const py::handle& obj, const char* name) {
  DArray a = DArray::ensure(obj);
  if (!a || a.ndim() != 2) throw std::invalid_argument(std::string(name) + ": expected a 2-D array (N, D)");
  return Eigen::Map<const RowMat>(a.data(), a.shape(0), a.shape(1));
}
VecX vecX(const py::handle& obj, const char* name) { return toMatrix(obj, 0, name).col(0); }
/// The targets y of the rows of X, one per row.
VecX targets(const py::handle& y, const MatX& X, const char* y_name, const char* x_name) {
  VecX v = vecX(y, y_name);
  if (v.size() != X.rows())
    throw std::invalid_argument(std::string(y_name) + ": length differs from the rows of " + x_name);
  return v;
}

SvgpTrainParams trainParams(const py::kwargs& kw) {
  SvgpTrainParams p;
  for (const auto& [key, value] : kw) {
    const std::string n = py::str(key);
    if (n == "epochs") p.epochs = py::cast<int>(value);
    else if (n == "batch_size") p.batch_size = py::cast<int>(value);
    else if (n == "seed") p.seed = py::cast<std::uint64_t>(value);
    else if (n == "lr") p.lr = py::cast<double>(value);
    else if (n == "lr_inducing") p.lr_inducing = py::cast<double>(value);
    else if (n == "lr_final_fraction") p.lr_final_fraction = py::cast<double>(value);
    else if (n == "natgrad_step") p.natgrad_step = py::cast<double>(value);
    else if (n == "lr_variational") p.lr_variational = py::cast<double>(value);
    else if (n == "train_inducing") p.train_inducing = py::cast<bool>(value);
    else if (n == "train_hyperparameters") p.train_hyperparameters = py::cast<bool>(value);
    else if (n == "min_noise_variance") p.min_noise_variance = py::cast<double>(value);
    else if (n == "num_threads") p.num_threads = py::cast<int>(value);
    else if (n == "final_full_data_q") p.final_full_data_q = py::cast<bool>(value);
    else if (n == "mode") {
      const auto s = py::cast<std::string>(value);
      if (s == "fast") p.mode = gp::ElboMode::kFast;
      else if (s == "exact") p.mode = gp::ElboMode::kExact;
      else throw std::invalid_argument("mode: expected 'fast' or 'exact', got '" + s + "'");
    } else {
      throw std::invalid_argument("unknown training parameter '" + n +
                                  "' (known: epochs, batch_size, seed, lr, lr_inducing, lr_final_fraction, "
                                  "natgrad_step, lr_variational, train_inducing, train_hyperparameters, "
                                  "min_noise_variance, num_threads, final_full_data_q, mode)");
    }
  }
  p.validate();
  return p;
}

/// on_epoch(dict) after every epoch, holding the GIL; empty when on_epoch is None.
std::function<void(const gp::EpochReport&)> epochCallback(const py::object& on_epoch) {
  if (on_epoch.is_none()) return {};
  return [&on_epoch](const gp::EpochReport& r) {
    py::gil_scoped_acquire acquire;
    py::dict d;
    d["epoch"] = r.epoch, d["epochs"] = r.epochs, d["elbo"] = r.elbo, d["val_rmse"] = r.val_rmse;
    d["elapsed_s"] = r.elapsed_s;
    on_epoch(d);
  };
}

/// The training summary as train_svgp returns it: the per-epoch history as arrays, and the totals.
py::dict trainSummaryDict(const gp::SvgpTrainSummary& s) {
  const auto n = static_cast<Eigen::Index>(s.history.size());
  RowMat h(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) h.row(i) << s.history[i].elbo, s.history[i].val_rmse, s.history[i].elapsed_s;
  py::dict d;
  d["elbo"] = toNumpy(h.col(0), true), d["val_rmse"] = toNumpy(h.col(1), true);
  d["elapsed_s"] = toNumpy(h.col(2), true), d["seconds"] = s.seconds, d["steps"] = s.steps;
  d["batches_per_epoch"] = s.batches_per_epoch, d["final_elbo"] = s.final_elbo;
  return d;
}

/// train_svgp: trains gp in place on (X, y), validated on (X_val, y_val) when given, without the GIL.
py::dict trainSvgpOnArrays(Svgp& gp, const py::handle& X, const py::handle& y, const py::object& X_val,
                           const py::object& y_val, const py::object& on_epoch, const py::kwargs& kw) {
  const SvgpTrainParams params = trainParams(kw);
  const MatX Xm = matX(X, "X");
  const VecX yv = targets(y, Xm, "y", "X");
  MatX Xv;
  VecX yvv;
  const bool has_val = !X_val.is_none();
  if (has_val) {
    Xv = matX(X_val, "X_val");
    yvv = targets(y_val, Xv, "y_val", "X_val");
  }
  const std::function<void(const gp::EpochReport&)> callback = epochCallback(on_epoch);
  gp::SvgpTrainSummary s;
  {
    py::gil_scoped_release release;
    s = gp::trainSvgp(gp, Xm, yv, params, has_val ? &Xv : nullptr, has_val ? &yvv : nullptr, callback);
  }
  return trainSummaryDict(s);
}

}  // namespace

void bindGpTrain(py::module_& m) {
  m.def(
      "kmeans_pp",
      [](const py::handle& X, int M, std::uint64_t seed, int lloyd_iterations, int max_points) {
        return toNumpy(gp::kmeansPlusPlus(matX(X, "X"), M, seed, lloyd_iterations, max_points));
      },
      py::arg("X"), py::arg("M"), py::arg("seed") = 1, py::arg("lloyd_iterations") = 10,
      py::arg("max_points") = 20000, "k-means++ seeding then Lloyd steps: (M, D) centres of the rows of X.");
  m.def(
      "init_svgp",
      [](const gp::Kernel& kernel, const py::handle& X, const py::handle& y, int num_inducing, std::uint64_t seed,
         bool standardize) {
        const MatX Xm = matX(X, "X");
        const VecX yv = targets(y, Xm, "y", "X");
        return gp::initSvgp(kernel, Xm, yv, num_inducing, seed,
                            standardize ? gp::InputNormalization::kStandardize : gp::InputNormalization::kNone);
      },
      py::arg("kernel"), py::arg("X"), py::arg("y"), py::arg("num_inducing"), py::arg("seed") = 1,
      py::arg("standardize") = false,
      "A fresh SVGP for (X, y): inducing points by k-means++, mean = mean(y), scales from var(y).");
  m.def(
      "train_svgp", &trainSvgpOnArrays, py::arg("gp"), py::arg("X"), py::arg("y"), py::arg("X_val") = py::none(),
      py::arg("y_val") = py::none(), py::arg("on_epoch") = py::none(),
      "Optimizes gp in place on (X, y) (Adam + natural gradients). Keyword arguments override SvgpTrainParams\n"
      "(epochs, batch_size, seed, lr, lr_inducing, natgrad_step, train_inducing, ...). on_epoch(dict) is called\n"
      "after every epoch. Returns {elbo, val_rmse, elapsed_s (per epoch), seconds, steps, batches_per_epoch,\n"
      "final_elbo (full-data ELBO per datum of the returned model)}. Equal-size minibatches (P40); q(v) ends at its\n"
      "full-data optimum (P41); num_threads share each minibatch (P42, 0: all cores).");
  m.def(
      "full_data_elbo",
      [](const Svgp& gp, const py::handle& X, const py::handle& y, int num_threads) {
        const MatX Xm = matX(X, "X");
        const VecX yv = targets(y, Xm, "y", "X");
        py::gil_scoped_release release;
        return gp::fullDataElbo(gp, Xm, yv, num_threads).elbo;
      },
      py::arg("gp"), py::arg("X"), py::arg("y"), py::arg("num_threads") = 1,
      "ELBO per datum over all of (X, y) (docs/math/gp.md P15, P41), in chunks.");
}

}  // namespace uwb::python
