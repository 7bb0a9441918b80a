"""uwbtdoa gp bindings: kernels by name and by composition, Gram matrices, SVGP predict / save / load."""
import numpy as np
import pytest

import uwbtdoa as u


@pytest.fixture
def X():
    return np.random.default_rng(11).uniform(-3, 3, (40, 2))


def test_presets_build_the_paper_kernels():
    assert u.Kernel.preset("z1").name == "(periodic[0]+periodic[1])"
    assert u.Kernel.preset("tdoa").input_dim == 6
    with pytest.raises(ValueError, match="unknown kernel preset 'foo'"):
        u.Kernel.preset("foo")


def test_composition_follows_the_sum_and_product_rules(X):
    # GIVEN two parts on different columns
    a, b = u.periodic([0], sigma2=0.7, l=0.8), u.matern52([1], sigma2=0.3, l=1.3)
    # THEN the composed kernels evaluate as sums and products of the parts
    np.testing.assert_allclose((a + b).gram(X), a.gram(X) + b.gram(X), rtol=1e-12)
    np.testing.assert_allclose((a * b).gram(X), a.gram(X) * b.gram(X), rtol=1e-12)
    c = u.rbf([0, 1], l=[0.5, 2.0])
    np.testing.assert_allclose(((a + b) * c).gram(X), (a.gram(X) + b.gram(X)) * c.gram(X), rtol=1e-12)
    assert (a + b)(X[0], X[1]) == pytest.approx((a + b).cross(X[:1], X[1:2])[0, 0])


def test_gram_is_symmetric_and_positive_semidefinite(X):
    for name in ("z1", "z2"):
        G = u.Kernel.preset(name).gram(X)
        np.testing.assert_allclose(G, G.T, atol=1e-14)
        assert np.linalg.eigvalsh(G).min() > -1e-10
    k = u.Kernel.preset("z1")
    k.set_param("p0.periodic.l", 0.5)
    assert k.param("p0.periodic.l") == 0.5
    with pytest.raises(ValueError):
        k.set_param("p0.periodic.l", -1.0)


def test_svgp_predicts_and_round_trips_through_json(tmp_path, X):
    gp = u.Svgp(u.Kernel.preset("z1"), X[:8])
    gp.mean_constant = 0.05
    gp.noise_variance = 0.01
    gp.set_variational(np.linspace(-1, 1, 8), np.eye(8) * 0.5)
    p = gp.predict(X)
    assert p["mean"].shape == (40,) and np.all(p["var_f"] > 0)
    np.testing.assert_allclose(p["var_y"], p["var_f"] + 0.01, rtol=1e-12)
    path = tmp_path / "model.json"
    gp.save(str(path))
    q = u.Svgp.load(str(path)).predict(X)
    np.testing.assert_allclose(q["mean"], p["mean"], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(q["var_f"], p["var_f"], rtol=1e-12)
    assert np.isfinite(gp.elbo(X, np.sin(X[:, 0]))["elbo"])
    big = np.tile(X, (20, 1))  # 800 rows: several blocks, so threads really split the work
    one, two = gp.predict(big), gp.predict(big, threads=2)
    for key in ("mean", "var_f", "var_y"):
        np.testing.assert_array_equal(one[key], two[key])


def test_svgp_errors(tmp_path, X):
    gp = u.Svgp(u.Kernel.preset("z1"), X[:5])
    with pytest.raises(ValueError, match="expected 2 columns"):
        gp.predict(np.zeros((3, 3)))
    with pytest.raises(OSError, match="cannot open model file"):
        u.Svgp.load(str(tmp_path / "absent.json"))
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(ValueError, match=r"bad.json:\d+:\d+: invalid JSON"):
        u.Svgp.load(str(bad))


def test_training_reduces_the_error_of_a_learnable_function():
    # GIVEN noisy samples of a smooth periodic function of two angles
    rng = np.random.default_rng(8)
    X = rng.uniform(-np.pi, np.pi, (1500, 2))
    y = 0.1 * np.sin(X[:, 0]) + 0.05 * np.cos(2 * X[:, 1]) + rng.normal(0, 0.02, len(X))
    gp = u.init_svgp(u.Kernel.preset("z1"), X, y, 20, seed=3)
    assert gp.num_inducing == 20
    epochs = []
    # WHEN it is trained
    summary = u.train_svgp(gp, X, y, epochs=15, batch_size=256, seed=3, on_epoch=epochs.append)
    # THEN the ELBO history is reported and the fit explains most of the variance
    assert len(epochs) == 15 and summary["elbo"].shape == (15,)
    rmse = np.sqrt(np.mean((gp.predict(X)["mean"] - y) ** 2))
    assert rmse < 0.5 * np.std(y)
    with pytest.raises(ValueError, match="unknown training parameter 'epoch'"):
        u.train_svgp(gp, X, y, epoch=3)
    Z = u.kmeans_pp(X, 7, seed=1)
    assert Z.shape == (7, 2)
