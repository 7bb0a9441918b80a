/** @file Kernel.cpp
 *  @brief The sum of products of kernel parts (docs/math/gp.md P5) over one flat parameter vector: parameters,
 *         the loops over terms of every evaluation path, JSON. The parts' formulas (P1–P4, P7–P10, P32) are in
 *         src/gp/kernels/, one file per part type.
 */
#include "uwb/gp/Kernel.h"

#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

namespace uwb::gp {

Kernel Kernel::sum(const std::vector<PartSpec>& parts) {
  std::vector<std::vector<int>> terms;
  for (int p = 0; p < static_cast<int>(parts.size()); ++p) terms.push_back({p});
  return Kernel(parts, terms);
}

Kernel Kernel::product(const std::vector<PartSpec>& parts) {
  std::vector<int> all;
  for (int p = 0; p < static_cast<int>(parts.size()); ++p) all.push_back(p);
  return Kernel(parts, {all});
}

Kernel::Kernel(const std::vector<PartSpec>& parts, const std::vector<std::vector<int>>& terms) { build(parts, terms); }

void Kernel::build(const std::vector<PartSpec>& parts, const std::vector<std::vector<int>>& terms) {
  if (parts.empty()) throw std::invalid_argument("kernel: no parts");
  std::vector<bool> used(parts.size(), false);
  for (const auto& t : terms) {
    if (t.empty()) throw std::invalid_argument("kernel: empty product term");
    for (int p : t) {
      if (p < 0 || p >= static_cast<int>(parts.size())) throw std::invalid_argument("kernel: term index out of range");
      if (used[p]) throw std::invalid_argument("kernel: a part appears in more than one term");
      used[p] = true;
    }
  }
  for (bool u : used)
    if (!u) throw std::invalid_argument("kernel: a part is in no term");
  ParamList params;
  PartList built;
  int input_dim = 0;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    built.push_back(makePart(parts[p], static_cast<int>(p), params));
    for (int d : parts[p].active_dims) input_dim = std::max(input_dim, d + 1);
  }
  parts_ = std::move(built);
  names_ = std::move(params.names);
  trainable_ = std::move(params.trainable);
  input_dim_ = input_dim;
  terms_ = terms;
  products_.clear();
  for (const auto& t : terms) products_.emplace_back(t);
  theta_ = Eigen::Map<const VecX>(params.values.data(), static_cast<Eigen::Index>(params.values.size()));
}

std::string Kernel::name() const {
  std::ostringstream os;
  os << '(';
  for (std::size_t t = 0; t < terms_.size(); ++t) {
    if (t) os << '+';
    for (std::size_t i = 0; i < terms_[t].size(); ++i) {
      if (i) os << '*';
      const KernelPart& p = *parts_[terms_[t][i]];
      os << toString(p.type()) << '[';
      for (std::size_t d = 0; d < p.activeDims().size(); ++d) os << (d ? "," : "") << p.activeDims()[d];
      os << ']';
    }
  }
  os << ')';
  return os.str();
}

void Kernel::setTheta(const VecX& theta) {
  if (theta.size() != theta_.size()) throw std::invalid_argument("kernel: wrong number of parameters");
  if (!(theta.array() > 0.0).all() || !theta.allFinite())
    throw std::invalid_argument("kernel: parameters must be positive and finite");
  theta_ = theta;
}

void Kernel::setTrainable(const std::string& name, bool trainable) {
  for (std::size_t i = 0; i < names_.size(); ++i) {
    if (names_[i] == name) {
      trainable_[i] = trainable;
      return;
    }
  }
  throw std::invalid_argument("unknown kernel parameter '" + name + "'");
}

std::map<std::string, Parameter> Kernel::params() const {
  std::map<std::string, Parameter> out;
  for (std::size_t i = 0; i < names_.size(); ++i) out[names_[i]] = {theta_[static_cast<Eigen::Index>(i)], trainable_[i]};
  return out;
}

void Kernel::setParam(const std::string& name, double value) {
  for (std::size_t i = 0; i < names_.size(); ++i) {
    if (names_[i] == name) {
      if (!(value > 0.0) || !std::isfinite(value))
        throw std::invalid_argument("kernel parameter " + name + " must be positive and finite");
      theta_[static_cast<Eigen::Index>(i)] = value;
      return;
    }
  }
  throw std::invalid_argument("unknown kernel parameter '" + name + "'");
}

double Kernel::param(const std::string& name) const {
  for (std::size_t i = 0; i < names_.size(); ++i)
    if (names_[i] == name) return theta_[static_cast<Eigen::Index>(i)];
  throw std::invalid_argument("unknown kernel parameter '" + name + "'");
}

PartSpec Kernel::partSpec(int p) const { return parts_[p]->spec(theta_, trainable_); }

// ---------------------------------------------------------------------------------------------------------------
// Evaluation: Σ over the products (P5)
// ---------------------------------------------------------------------------------------------------------------

MatX Kernel::partCross(int p, const MatX& X1, const MatX& X2) const {
  const KernelPart& part = *parts_[p];
  return part.block(activeColumns(X1, part.activeDims()), activeColumns(X2, part.activeDims()), theta_);
}

MatX Kernel::cross(const MatX& X1, const MatX& X2, std::vector<MatX>* part_blocks) const {
  if (X1.cols() < input_dim_ || X2.cols() < input_dim_)
    throw std::invalid_argument("kernel: inputs have " + std::to_string(std::min(X1.cols(), X2.cols())) +
                                " columns, the kernel reads " + std::to_string(input_dim_));
  MatX K;
  if (part_blocks) part_blocks->assign(parts_.size(), MatX());
  for (const Product& term : products_) {
    if (term.factors().size() == 1 && !part_blocks) {
      if (K.size() == 0)
        K = partCross(term.factors()[0], X1, X2);
      else
        K += partCross(term.factors()[0], X1, X2);
      continue;
    }
    if (K.size() == 0) K = MatX::Zero(X1.rows(), X2.rows());
    K += term.block(parts_, X1, X2, theta_, part_blocks);
  }
  return K;
}

void Kernel::crossInto(const MatX& X1, const MatX& X2, Eigen::Ref<MatX> K) const {
  if (X1.cols() < input_dim_ || X2.cols() < input_dim_)
    throw std::invalid_argument("kernel: inputs have " + std::to_string(std::min(X1.cols(), X2.cols())) +
                                " columns, the kernel reads " + std::to_string(input_dim_));
  const Eigen::Index n1 = X1.rows(), n2 = X2.rows();
  if (K.rows() != n1 || K.cols() != n2) throw std::invalid_argument("kernel crossInto: output has the wrong size");
  // Per part: the active columns prepared once, then one column of the part per row of X2, vectorized over the
  // rows of X1.
  std::vector<std::unique_ptr<PreparedBlock>> prepared(parts_.size());
  for (std::size_t p = 0; p < parts_.size(); ++p) {
    const KernelPart& part = *parts_[p];
    prepared[p] = part.prepare(activeColumns(X1, part.activeDims()), activeColumns(X2, part.activeDims()), theta_);
  }
  Eigen::ArrayXd term(n1), part(n1);
  for (Eigen::Index j = 0; j < n2; ++j) {
    // K = Σ_terms Π_parts (P5), summed in the order of cross(); the first term is written into K directly
    auto Kj = K.col(j).array();
    for (std::size_t t = 0; t < products_.size(); ++t) {
      products_[t].column(parts_, prepared, j, theta_, t == 0 ? K.col(j).data() : term.data(), part);
      if (t > 0) Kj += term;
    }
  }
}

void Kernel::crossColumn(const MatX& X1, const Eigen::Ref<const RowVecX>& x, Eigen::Ref<VecX> out) const {
  if (X1.cols() < input_dim_ || x.size() < input_dim_)
    throw std::invalid_argument("kernel: inputs have too few columns for the kernel");
  if (out.size() != X1.rows()) throw std::invalid_argument("kernel crossColumn: output has the wrong size");
  const Eigen::Index n1 = X1.rows();
  out.setZero();
  for (Eigen::Index i0 = 0; i0 < n1; i0 += kChunkRows) {
    const Eigen::Index c = std::min<Eigen::Index>(kChunkRows, n1 - i0);
    for (const Product& term : products_) {
      Chunk prod = Chunk::Ones(c);
      term.multiplyChunk(parts_, X1, i0, x, theta_, prod);
      out.segment(i0, c).array() += prod;
    }
  }
}

double Kernel::operator()(const Eigen::Ref<const RowVecX>& x, const Eigen::Ref<const RowVecX>& xp) const {
  return cross(MatX(x), MatX(xp))(0, 0);
}

double Kernel::diagValue() const {
  double k = 0.0;
  for (const Product& term : products_) k += term.diagValue(parts_, theta_);
  return k;
}

VecX Kernel::diag(const MatX& X) const { return VecX::Constant(X.rows(), diagValue()); }

void Kernel::accumulateDiagGradient(double sum_g, VecX& grad_theta) const {
  for (const Product& term : products_) term.accumulateDiagGradient(parts_, theta_, sum_g, grad_theta);
}

void Kernel::accumulateCrossGradient(const MatX& X1, const MatX& X2, const MatX& G,
                                     const std::vector<MatX>& part_blocks, VecX& grad_theta, MatX* grad_X1) const {
  if (static_cast<int>(part_blocks.size()) != numParts())
    throw std::invalid_argument("kernel gradient: part_blocks missing (call cross(X1, X2, &blocks))");
  for (const Product& term : products_) term.accumulateGradient(parts_, X1, X2, G, part_blocks, theta_, grad_theta, grad_X1);
}

// ---------------------------------------------------------------------------------------------------------------
// JSON
// ---------------------------------------------------------------------------------------------------------------

nlohmann::json Kernel::toJson() const {
  nlohmann::json parts = nlohmann::json::array();
  for (int p = 0; p < numParts(); ++p) {
    const PartSpec s = partSpec(p);
    nlohmann::json jp;
    jp["type"] = toString(s.type);
    jp["active_dims"] = s.active_dims;
    partSpecToJson(s, jp);
    parts.push_back(jp);
  }
  nlohmann::json fixed = nlohmann::json::array();
  for (std::size_t i = 0; i < names_.size(); ++i)
    if (!trainable_[i]) fixed.push_back(names_[i]);
  return {{"combination", "sum_of_products"}, {"terms", terms_}, {"parts", parts}, {"fixed", fixed},
          {"name", name()}};
}

namespace {
/// An array of small non-negative integers (dimension or part indices), checked before conversion: get<int>() of
/// a value like 1e300 would overflow (undefined behaviour).
std::vector<int> indicesFromJson(const nlohmann::json& j, const char* what) {
  if (!j.is_array()) throw std::invalid_argument(std::string(what) + ": expected an array of indices");
  std::vector<int> out;
  for (const auto& v : j) {
    if (!v.is_number_integer() || v.get<std::int64_t>() < 0 || v.get<std::int64_t>() > 1000)
      throw std::invalid_argument(std::string(what) + ": expected integer indices in [0, 1000], got " + v.dump());
    out.push_back(static_cast<int>(v.get<std::int64_t>()));
  }
  return out;
}
}  // namespace

Kernel Kernel::fromJson(const nlohmann::json& j) {
  try {
    std::vector<PartSpec> specs;
    for (const auto& jp : j.at("parts")) {
      PartSpec s;
      s.type = partTypeFromString(jp.at("type").get<std::string>());
      s.active_dims = indicesFromJson(jp.at("active_dims"), "active_dims");
      // Either our own layout or the fixture layout (parameters in a "paper" block; FIXTURES.md §2).
      partSpecFromJson(jp.contains("paper") ? jp.at("paper") : jp, jp, s);
      specs.push_back(s);
    }
    std::vector<std::vector<int>> terms;
    const std::string comb = j.value("combination", std::string("sum"));
    if (comb == "sum") {
      for (int p = 0; p < static_cast<int>(specs.size()); ++p) terms.push_back({p});
    } else if (comb == "product") {
      terms.emplace_back();
      for (int p = 0; p < static_cast<int>(specs.size()); ++p) terms[0].push_back(p);
    } else if (comb == "sum_of_products") {
      for (const auto& t : j.at("terms")) terms.push_back(indicesFromJson(t, "terms"));
    } else {
      throw std::invalid_argument("unknown combination '" + comb + "'");
    }
    Kernel k(specs, terms);
    if (j.contains("fixed"))
      for (const auto& n : j.at("fixed")) k.setTrainable(n.get<std::string>(), false);
    return k;
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(std::string("kernel JSON: ") + e.what());
  }
}

}  // namespace uwb::gp
