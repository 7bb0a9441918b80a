/** @file bind_gp.cpp
 *  @brief Python bindings of uwb/gp: composite kernels (by preset name or composed with + and *), Gram matrices,
 *  and the whitened SVGP (parameters, ELBO, predictions of mean and variance, JSON save/load).
 *
 *  Inputs are rows: X is (N, D) float64. Kernel parts are built with periodic(), matern52(), rbf(), ledergerber()
 *  and combined with + (sum) and * (product; a product of sums is distributed, and parts that then appear in
 *  several terms are copied, each copy keeping its own hyperparameters).
 */
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bindings.h"
#include "uwb/core/Error.h"
#include "uwb/gp/Kernel.h"
#include "uwb/gp/Svgp.h"
#include "uwb/io/FileAccess.h"
#include "uwb/io/JsonFile.h"

namespace uwb::python {
namespace {

using gp::Kernel;
using gp::PartSpec;
using gp::PartType;
using gp::Svgp;

MatX toMatX(const py::handle& obj, const char* name, Eigen::Index cols = -1) {
  DArray a = DArray::ensure(obj);
  if (!a || a.ndim() != 2) throw std::invalid_argument(std::string(name) + ": expected a 2-D array (N, D)");
  if (cols >= 0 && a.shape(1) != cols) {
    throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(cols) + " columns, got " +
                                std::to_string(a.shape(1)));
  }
  return Eigen::Map<const RowMat>(a.data(), a.shape(0), a.shape(1));
}

VecX toVecX(const py::handle& obj, const char* name) { return toMatrix(obj, 0, name).col(0); }

std::vector<PartSpec> partsOf(const Kernel& k) {
  std::vector<PartSpec> parts;
  for (int p = 0; p < k.numParts(); ++p) parts.push_back(k.partSpec(p));
  return parts;
}

Kernel combineSum(const Kernel& a, const Kernel& b) {
  std::vector<PartSpec> parts = partsOf(a);
  for (const auto& s : partsOf(b)) parts.push_back(s);
  std::vector<std::vector<int>> terms = a.terms();
  for (auto t : b.terms()) {
    for (int& i : t) i += a.numParts();
    terms.push_back(t);
  }
  Kernel k(parts, terms);
  return k;
}

/// (Σ_i A_i)(Σ_j B_j) = Σ_ij A_i B_j; every part used in more than one term is copied.
Kernel combineProduct(const Kernel& a, const Kernel& b) {
  const std::vector<PartSpec> pa = partsOf(a), pb = partsOf(b);
  std::vector<PartSpec> parts;
  std::vector<std::vector<int>> terms;
  for (const auto& ta : a.terms()) {
    for (const auto& tb : b.terms()) {
      std::vector<int> term;
      for (int i : ta) term.push_back(static_cast<int>(parts.size())), parts.push_back(pa[i]);
      for (int i : tb) term.push_back(static_cast<int>(parts.size())), parts.push_back(pb[i]);
      terms.push_back(term);
    }
  }
  return Kernel(parts, terms);
}

std::vector<double> listOf(const py::handle& v) {
  if (py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v)) return {py::cast<double>(v)};
  const RowMat m = toMatrix(v, 0, "kernel parameter");
  return std::vector<double>(m.data(), m.data() + m.size());
}

Kernel onePart(PartType type, const std::vector<int>& dims, double sigma2, const py::handle& l, const py::handle& T,
               double t1, double t2, bool train_period) {
  PartSpec s;
  s.type = type;
  s.active_dims = dims;
  s.sigma2 = sigma2;
  s.l = listOf(l);
  s.T = listOf(T);
  s.t1 = t1;
  s.t2 = t2;
  s.train_period = train_period;
  return Kernel::sum({s});
}

py::dict paramsDict(const std::map<std::string, gp::Parameter>& params) {
  py::dict d;
  for (const auto& [name, p] : params) d[py::str(name)] = py::make_tuple(p.value, p.trainable);
  return d;
}

py::dict predictionDict(const gp::SvgpPrediction& p) {
  py::dict d;
  d["mean"] = toNumpy(p.mean, true), d["var_f"] = toNumpy(p.var_f, true), d["var_y"] = toNumpy(p.var_y, true);
  return d;
}

/// The one JSON reader (io/JsonFile.h): located errors, nesting capped at kMaxJsonDepth before parsing.
nlohmann::json parseJson(const std::string& text, const std::string& source) {
  return parseJsonText(text, source, "JSON");
}

std::string readText(const std::string& path) { return readTextFile(path, "model file"); }

void writeText(const std::string& text, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw FileError("cannot write model file '" + path + "'");
  out << text;
  if (!out) throw FileError("error writing model file '" + path + "'");
}

void bindKernel(py::module_& m) {
  py::class_<Kernel>(m, "Kernel",
                     "Composite GP kernel: a sum of products of parts, each reading its own input columns.\n"
                     "Build with Kernel.preset('z1'|'z2'|'tdoa') or compose periodic(), matern52(), rbf(),\n"
                     "ledergerber() with + and *.")
      .def_static("preset", &Kernel::preset, py::arg("name"),
                  "Paper kernels on the bias-model feature columns: 'z1' (eq. 7), 'z2' (eq. 8), 'tdoa' (eq. 9).")
      .def_property_readonly("name", &Kernel::name, "kernel expression, e.g. 'periodic(0)*matern52(1)'")
      .def_property_readonly("input_dim", &Kernel::inputDim, "number of input columns the kernel reads")
      .def_property_readonly("num_params", &Kernel::numParams, "number of hyperparameters (len(theta))")
      .def_property_readonly("terms", &Kernel::terms, "the kernels of a sum or product (itself for a single kernel)")
      .def_property("theta", [](const Kernel& k) { return toNumpy(k.theta(), true); },
                    [](Kernel& k, const py::handle& v) { k.setTheta(toVecX(v, "theta")); },
                    "flat vector of positive hyperparameter values (names: param_names)")
      .def_property_readonly("param_names", &Kernel::paramNames, "names of the entries of theta")
      .def("params", [](const Kernel& k) { return paramsDict(k.params()); }, "{name: (value, trainable)}")
      .def("param", &Kernel::param, py::arg("name"), "Value of one named hyperparameter.")
      .def("set_param", &Kernel::setParam, py::arg("name"), py::arg("value"), "Sets one named hyperparameter.")
      .def("set_trainable", &Kernel::setTrainable, py::arg("name"), py::arg("trainable"),
           "Fixes (False) or frees (True) one named hyperparameter for training.")
      .def("__call__",
           [](const Kernel& k, const py::handle& x, const py::handle& xp) {
             const RowMat a = toMatrix(x, 0, "x"), b = toMatrix(xp, 0, "x'");
             return k(Eigen::Map<const RowVecX>(a.data(), a.size()), Eigen::Map<const RowVecX>(b.data(), b.size()));
           },
           py::arg("x"), py::arg("xp"), "k(x, x') for two single points (1-D arrays)")
      .def("cross",
           [](const Kernel& k, const py::handle& X1, const py::handle& X2) {
             return toNumpy(k.cross(toMatX(X1, "X1"), toMatX(X2, "X2")));
           },
           py::arg("X1"), py::arg("X2"), "K(X1, X2): (n1, n2)")
      .def("gram", [](const Kernel& k, const py::handle& X) { return toNumpy(k.gram(toMatX(X, "X"))); }, py::arg("X"),
           "K(X, X): (n, n)")
      .def("diag", [](const Kernel& k, const py::handle& X) { return toNumpy(k.diag(toMatX(X, "X")), true); },
           py::arg("X"), "diag K(X, X): (n,)")
      .def("to_json", [](const Kernel& k) { return k.toJson().dump(); }, "The kernel as JSON text.")
      .def_static("from_json", [](const std::string& s) { return Kernel::fromJson(parseJson(s, "kernel JSON")); },
                  py::arg("text"), "A kernel from the JSON text of to_json().")
      .def("__add__", &combineSum, py::is_operator())
      .def("__mul__", &combineProduct, py::is_operator())
      .def("__repr__", [](const Kernel& k) { return "<Kernel " + k.name() + ">"; });
}

/// The kernel parts, each as a one-part Kernel: periodic(), matern52(), rbf(), ledergerber().
void bindKernelParts(py::module_& m) {
  const auto l_default = py::float_(1.0);
  m.def(
      "periodic",
      [](const std::vector<int>& dims, double sigma2, const py::handle& l, const py::handle& T, bool train_period) {
        return onePart(PartType::kPeriodic, dims, sigma2, l, T, 1.0, 1.0, train_period);
      },
      py::arg("dims"), py::arg("sigma2") = 1.0, py::arg("l") = l_default, py::arg("T") = py::float_(2.0 * kPi),
      py::arg("train_period") = false,
      "Periodic part σ² exp(−2 Σ sin²(π|x−x'|/T)/l²) on input columns dims (paper k_p, eq. 7).");
  m.def(
      "matern52",
      [](const std::vector<int>& dims, double sigma2, const py::handle& l) {
        return onePart(PartType::kMatern52, dims, sigma2, l, py::float_(1.0), 1.0, 1.0, false);
      },
      py::arg("dims"), py::arg("sigma2") = 1.0, py::arg("l") = l_default, "Matérn 5/2 part (paper eq. 8).");
  m.def(
      "rbf",
      [](const std::vector<int>& dims, double sigma2, const py::handle& l) {
        return onePart(PartType::kRbf, dims, sigma2, l, py::float_(1.0), 1.0, 1.0, false);
      },
      py::arg("dims"), py::arg("sigma2") = 1.0, py::arg("l") = l_default, "Squared-exponential part.");
  m.def(
      "ledergerber",
      [](const std::vector<int>& dims, double t0, double t1, double t2) {
        return onePart(PartType::kLedergerber, dims, t0, py::float_(1.0), py::float_(1.0), t1, t2, false);
      },
      py::arg("dims"), py::arg("t0") = 1.0, py::arg("t1") = 1.0, py::arg("t2") = 1.0,
      "Ledergerber–D'Andrea part θ0 exp(−(1 − cos∠(x,x'))/θ1 − (‖x‖−‖x'‖)²/θ2) on 3 columns (paper k_L, eq. 9).");
}

py::dict svgpElbo(const Svgp& g, const py::handle& X, const py::handle& y, double num_data) {
  const MatX Xm = toMatX(X, "X");
  const VecX yv = toVecX(y, "y");
  if (yv.size() != Xm.rows()) throw std::invalid_argument("y: length differs from the rows of X");
  const gp::ElboTerms t = g.elbo(Xm, yv, num_data < 0 ? static_cast<double>(Xm.rows()) : num_data);
  py::dict d;
  d["elbo"] = t.elbo, d["kl"] = t.kl, d["exp_log_lik"] = t.exp_log_lik, d["exp_log_lik_sum"] = t.exp_log_lik_sum;
  return d;
}

py::dict svgpPredict(const Svgp& g, const py::handle& X, int threads) {
  const MatX Xm = toMatX(X, "X", g.inputDim());
  gp::SvgpPrediction p;
  {
    py::gil_scoped_release release;
    p = g.predictor().predict(Xm, threads);
  }
  return predictionDict(p);
}

void bindSvgp(py::module_& m) {
  py::class_<Svgp>(m, "Svgp",
                   "Whitened sparse variational GP with a Gaussian likelihood and a constant mean (Hensman 2013).")
      .def(py::init([](const Kernel& k, const py::handle& Z, double jitter) {
             return Svgp(k, toMatX(Z, "Z"), jitter);
           }),
           py::arg("kernel"), py::arg("Z"), py::arg("jitter") = Svgp::kDefaultJitter,
           "SVGP with inducing points Z (M, D); q(u) = prior, mean 0, noise variance 0.1.")
      .def_property("kernel", [](const Svgp& g) { return g.kernel(); },
                    [](Svgp& g, const Kernel& k) { g.kernel() = k; }, "the covariance function (a Kernel)")
      .def_property("inducing", [](const Svgp& g) { return toNumpy(g.inducing()); },
                    [](Svgp& g, const py::handle& Z) { g.setInducing(toMatX(Z, "Z")); },
                    "(M, D) inducing points (in the transformed input space)")
      .def_property_readonly("variational_mean", [](const Svgp& g) { return toNumpy(g.variationalMean(), true); },
                             "(M,) mean m of q(u)")
      .def_property_readonly("variational_cholesky", [](const Svgp& g) { return toNumpy(g.variationalCholesky()); },
                             "(M, M) lower Cholesky factor L of the covariance of q(u) = N(m, L Lᵀ)")
      .def("set_variational",
           [](Svgp& g, const py::handle& mean, const py::handle& L) {
             g.setVariational(toVecX(mean, "m"), toMatX(L, "L"));
           },
           py::arg("m"), py::arg("L"), "Sets q(u) = N(m, L Lᵀ): mean m (M,) and lower Cholesky factor L (M, M).")
      .def_property("mean_constant", &Svgp::meanConstant, &Svgp::setMean, "constant prior mean of the GP")
      .def_property("noise_variance", &Svgp::noiseVariance, &Svgp::setNoiseVariance, "Gaussian likelihood variance σ_n²")
      .def_property_readonly("jitter", &Svgp::jitter, "diagonal jitter added to K_uu")
      .def_property_readonly("num_inducing", &Svgp::numInducing, "number of inducing points M")
      .def_property_readonly("input_dim", &Svgp::inputDim, "input dimension D")
      .def("set_input_transform",
           [](Svgp& g, const py::handle& shift, const py::handle& scale) {
             g.setInputTransform(toVecX(shift, "shift"), toVecX(scale, "scale"));
           },
           py::arg("shift"), py::arg("scale"), "x̃ = (x − shift) / scale before the kernel (empty = identity)")
      .def_property_readonly("input_shift", [](const Svgp& g) { return toNumpy(g.inputShift(), true); },
                             "shift of the input transform (empty: none)")
      .def_property_readonly("input_scale", [](const Svgp& g) { return toNumpy(g.inputScale(), true); },
                             "scale of the input transform (empty: none)")
      .def("params", [](const Svgp& g) { return paramsDict(g.params()); }, "{name: (value, trainable)}")
      .def("set_param", &Svgp::setParam, py::arg("name"), py::arg("value"), "Sets one named parameter (see params()).")
      .def("kl", &Svgp::kl, "KL(q(u) ‖ p(u)) [nats], the ELBO's regularizer.")
      .def("elbo", &svgpElbo, py::arg("X"), py::arg("y"), py::arg("num_data") = -1.0,
           "Minibatch ELBO per datum (num_data defaults to len(y)): {elbo, kl, exp_log_lik, exp_log_lik_sum}")
      .def("predict", &svgpPredict, py::arg("X"), py::arg("threads") = 1,
           "Predictions at raw inputs X (N, D): {mean, var_f (latent), var_y (= var_f + noise)}. threads > 1 splits "
           "the rows over that many threads (0: one per core); the result does not depend on it.")
      .def("to_json", [](const Svgp& g) { return g.toJson().dump(); }, "The model as JSON text (Svgp::toJson).")
      .def_static("from_json", [](const std::string& s) { return Svgp::fromJson(parseJson(s, "SVGP JSON")); },
                  py::arg("text"), "A model from the JSON text of to_json().")
      .def("save", [](const Svgp& g, const std::string& path) { writeText(g.toJson().dump(1), path); },
           py::arg("path"), "Writes the model as JSON (Svgp::toJson); OSError when the file cannot be written.")
      .def_static(
          "load", [](const std::string& path) { return Svgp::fromJson(parseJson(readText(path), path)); },
          py::arg("path"), "Reads a model written by save(); OSError / ValueError on failure.")
      .def("__repr__", [](const Svgp& g) {
        return "<Svgp M=" + std::to_string(g.numInducing()) + " D=" + std::to_string(g.inputDim()) + " kernel " +
               g.kernel().name() + ">";
      });
}

}  // namespace

void bindGp(py::module_& m) {
  bindKernel(m);
  bindKernelParts(m);
  bindSvgp(m);
}

}  // namespace uwb::python
