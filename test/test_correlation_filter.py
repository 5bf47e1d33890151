"""What the scale and the translation filter share (iemd_ros/correlation_filter.py)."""
import numpy as np
import pytest

from iemd_ros.tracking.correlation_filter import FLOOR, FilterModel, hann, model_size, orientation_histograms, parabola_peak


def test_orientation_histograms_of_edges_by_hand():
    """A vertical step edge 0 -> 1 between columns 3 and 4 of a 4x8 window: central differences give
    0.5 at columns 3 and 4 (horizontal gradient, orientation 0: bin 0), so each 4x4 cell holds 4 x 0.5 = 2
    in bin 0, divided by 2 + FLOOR.  The reversed edge falls in the same (unsigned) bin; a horizontal edge
    (orientation 90 degrees) in bin 4 (20-degree bins); a diagonal ramp (45 degrees) in bin 2."""
    step = np.zeros((4, 8), np.float32)
    step[:, 4:] = 1.0
    expected = np.zeros((2, 9))
    expected[:, 0] = 2.0 / (2.0 + FLOOR)
    out = orientation_histograms(np.stack([step, 1.0 - step]))
    np.testing.assert_allclose(out, np.stack([expected.ravel()] * 2), rtol=1e-6)

    horizontal = np.zeros((8, 4), np.float32)
    horizontal[4:] = 1.0
    assert np.flatnonzero(orientation_histograms(horizontal[None]).reshape(2, 9).sum(0)).tolist() == [4]
    ramp = np.add.outer(np.arange(8.0), np.arange(8.0)).astype(np.float32)[None] / 16.0
    assert np.flatnonzero(orientation_histograms(ramp).reshape(4, 9).sum(0)).tolist() == [2]
    assert not orientation_histograms(np.full((1, 8, 8), 0.5, np.float32)).any()  # flat: no gradient, zeros
    with pytest.raises(ValueError, match="multiple of the 4 px cell"):
        orientation_histograms(np.zeros((1, 6, 8), np.float32))


def test_parabola_peak_by_hand():
    """Samples of y = -(x - 0.25)^2 at -1, 0, 1 have their vertex at 0.25; a flat or convex triple gives 0."""
    assert parabola_peak(-1.5625, -0.0625, -0.5625) == pytest.approx(0.25)
    assert parabola_peak(1.0, 1.0, 1.0) == 0.0
    assert parabola_peak(1.0, 0.0, 1.0) == 0.0


def test_filter_model_answers_its_training_sample_with_the_desired_response():
    """One channel, one sample f with desired response g: H = G conj(F) / (|F|^2 + lambda), so the response
    to f is G |F|^2 / (|F|^2 + lambda), g itself as lambda -> 0; a shifted sample shifts the response."""
    rng = np.random.default_rng(0)
    sample = np.fft.fft(rng.normal(size=32))[None]  # (1 channel, 32)
    desired = np.fft.fft(np.exp(-0.5 * ((np.arange(32) - 16) / 2.0) ** 2))
    model = FilterModel(learning_rate=0.1, regularization=1e-9, channel_axis=0)
    assert not model.trained
    model.learn(desired, sample)
    assert model.trained
    np.testing.assert_allclose(np.fft.ifft(model.response(sample)).real, np.fft.ifft(desired).real, atol=1e-6)
    shifted = sample * np.exp(-2j * np.pi * np.fft.fftfreq(32) * 5)  # the signal moved 5 samples on
    assert int(np.argmax(np.fft.ifft(model.response(shifted)).real)) == 21


def test_filter_model_keeps_running_averages_at_its_learning_rate():
    """The first sample replaces the model, each later one is blended in at eta (DSST eq. 5); reset forgets."""
    rng = np.random.default_rng(1)
    desired = np.fft.fft(rng.normal(size=16))
    first, second = (np.fft.fft(rng.normal(size=(3, 16)), axis=1) for _ in range(2))
    model = FilterModel(learning_rate=0.25, regularization=0.01, channel_axis=0)
    model.learn(desired, first)
    model.learn(desired, second)
    numerator = 0.75 * desired * np.conj(first) + 0.25 * desired * np.conj(second)
    denominator = 0.75 * (np.abs(first) ** 2).sum(0) + 0.25 * (np.abs(second) ** 2).sum(0)
    probe = np.fft.fft(rng.normal(size=(3, 16)), axis=1)
    np.testing.assert_allclose(model.response(probe), (numerator * probe).sum(0) / (denominator + 0.01))
    model.reset()
    assert not model.trained
    with pytest.raises(ValueError, match="learning_rate"):
        FilterModel(learning_rate=0.0, regularization=0.01, channel_axis=0)


def test_model_size_and_taper_by_hand():
    """100 x 50 px to about 512 px: scaled by sqrt(512 / 5000) = 0.32 to 32 x 16, whole 4-px cells; a tiny window
    keeps min_cells cells per axis.  The taper has no zero ends and peaks in the middle."""
    assert model_size((100.0, 50.0), 512, min_cells=2) == (32, 16)
    assert model_size((4.0, 400.0), 512, min_cells=2) == (8, 228)
    taper = hann(5)
    np.testing.assert_allclose(taper, [0.25, 0.75, 1.0, 0.75, 0.25])
