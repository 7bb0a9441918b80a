/** @file bind_model.cpp
 *  @brief Python bindings of uwb/model: TDoA prediction (paper eq. 2) and the GP inputs (TdoaFeature), vectorized.
 */
#include "bindings.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/model/TdoaFeature.h"
#include "uwb/model/TdoaModel.h"

namespace uwb::python {

RowMat anchorPositions(const AnchorSurvey& survey, const Eigen::VectorXi& ids);  // bind_io.cpp

namespace {

py::dict featuresDict(const Eigen::VectorXi& id_a, const Eigen::VectorXi& id_b, const RowMat& p, const RowMat& q,
                      const RowMat& pa, const RowMat& pb, Eigen::Index n) {
  std::vector<TdoaFeature> fs;
  fs.reserve(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    fs.push_back(makeTdoaFeature(id_a(id_a.size() == 1 ? 0 : i), id_b(id_b.size() == 1 ? 0 : i), row3(p, i),
                                 rowQuat(q, i), row3(pa, i), row3(pb, i)));
  }
  std::vector<const TdoaFeature*> ptrs;
  for (const TdoaFeature& f : fs) ptrs.push_back(&f);
  return featuresToDict(ptrs);
}

}  // namespace

void bindModel(py::module_& m) {
  m.def(
      "predict_tdoa",
      [](const py::handle& w_p_b, const py::handle& w_q_b, const py::handle& anchor_a, const py::handle& anchor_b,
         const py::handle& b_t_tag) {
        const RowMat p = toMatrix(w_p_b, 3, "w_p_b"), q = toMatrix(w_q_b, 4, "w_q_b");
        const RowMat pa = toMatrix(anchor_a, 3, "anchor_a"), pb = toMatrix(anchor_b, 3, "anchor_b");
        const Vec3 tag = b_t_tag.is_none() ? kUtilTagOffset_b : row3(toMatrix(b_t_tag, 3, "b_t_tag"), 0);
        const Eigen::Index n =
            commonRows({{p.rows(), "w_p_b"}, {q.rows(), "w_q_b"}, {pa.rows(), "anchor_a"}, {pb.rows(), "anchor_b"}});
        Eigen::VectorXd z(n);
        for (Eigen::Index i = 0; i < n; ++i) z(i) = predictTdoa(row3(p, i), rowQuat(q, i), tag, row3(pa, i), row3(pb, i));
        return toNumpy(z, true);
      },
      py::arg("w_p_b"), py::arg("w_q_b"), py::arg("anchor_a"), py::arg("anchor_b"), py::arg("b_t_tag") = py::none(),
      "Noise-free TDoA |p_tag − a_B| − |p_tag − a_A| [m] (paper eq. 2, UTIL sign) for N poses.\n"
      "w_p_b (N, 3) [m], w_q_b (N, 4) (x, y, z, w), anchor_a/anchor_b (N, 3) or (3,); b_t_tag defaults to the UTIL\n"
      "tag offset. Returns (N,).");
  m.def(
      "make_tdoa_features",
      [](const py::handle& id_a, const py::handle& id_b, const py::handle& w_p_b, const py::handle& w_q_b,
         const py::handle& anchor_a, const py::handle& anchor_b) {
        const Eigen::VectorXi ia = toIntVector(id_a, "id_a"), ib = toIntVector(id_b, "id_b");
        const RowMat p = toMatrix(w_p_b, 3, "w_p_b"), q = toMatrix(w_q_b, 4, "w_q_b");
        const RowMat pa = toMatrix(anchor_a, 3, "anchor_a"), pb = toMatrix(anchor_b, 3, "anchor_b");
        const Eigen::Index n = commonRows({{ia.size(), "id_a"}, {ib.size(), "id_b"}, {p.rows(), "w_p_b"},
                                           {q.rows(), "w_q_b"}, {pa.rows(), "anchor_a"}, {pb.rows(), "anchor_b"}});
        return featuresDict(ia, ib, p, q, pa, pb, n);
      },
      py::arg("id_a"), py::arg("id_b"), py::arg("w_p_b"), py::arg("w_q_b"), py::arg("anchor_a"), py::arg("anchor_b"),
      "GP inputs (TdoaFeature) of N measurements from poses and anchor positions. Returns a dict of arrays:\n"
      "id_a, id_b, b_p_a (N, 3), b_p_b (N, 3) [anchor relative to the body, body frame, m], yaw_a, yaw_b [rad]\n"
      "(azimuth of each anchor in the body frame, the paper's α), w_p_b (N, 3), w_p_anchor_a, w_p_anchor_b (N, 3)\n"
      "[anchor positions, world frame, m].");
  m.def(
      "tdoa_features",
      [](const AnchorSurvey& survey, const py::handle& id_a, const py::handle& id_b, const py::handle& w_p_b,
         const py::handle& w_q_b) {
        const Eigen::VectorXi ia = toIntVector(id_a, "id_a"), ib = toIntVector(id_b, "id_b");
        const RowMat p = toMatrix(w_p_b, 3, "w_p_b"), q = toMatrix(w_q_b, 4, "w_q_b");
        const Eigen::Index n =
            commonRows({{ia.size(), "id_a"}, {ib.size(), "id_b"}, {p.rows(), "w_p_b"}, {q.rows(), "w_q_b"}});
        return featuresDict(ia, ib, p, q, anchorPositions(survey, ia), anchorPositions(survey, ib), n);
      },
      py::arg("survey"), py::arg("id_a"), py::arg("id_b"), py::arg("w_p_b"), py::arg("w_q_b"),
      "Like make_tdoa_features, with the anchor positions looked up by id in the survey.");
}

}  // namespace uwb::python
