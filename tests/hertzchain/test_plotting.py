import matplotlib.pyplot as plt
import numpy as np

from hertzchain import plotting


def test_plots_draw_on_given_axes(tmp_path, rng):
    fig, axes = plt.subplots(2, 3)
    plotting.plot_grain_profile(axes[0, 0], rng.normal(size=50), interface=25)
    plotting.plot_vmax(axes[0, 1], rng.uniform(0.6, 0.7, 50), mean=0.68, grain_range=(10, 40))
    t = np.linspace(0, 1e-3, 30)
    u = np.cumsum(rng.uniform(size=(30, 3)), axis=0)
    plotting.plot_displacement_time(axes[0, 2], t, u, [5, 6, 7], free_flight=u > 10)
    im = plotting.plot_spacetime(axes[1, 0], t, rng.uniform(size=(30, 50)), interface=25,
                                 label="e/e0")
    plotting.plot_theory_lines(axes[1, 1])
    fig.savefig(tmp_path / "x.png")
    assert im.get_array().shape == (30, 50)
    # grain indices count from 0 (docs/guide/cli.md): the interface of 25 grains on the
    # left sits between grains 24 and 25, and the first grain is at 0
    assert axes[0, 0].get_xlabel() == "grain index $i$"
    assert any(np.allclose(line.get_xdata(), 24.5) for line in axes[0, 0].lines)
    assert axes[0, 0].lines[0].get_xdata()[0] == 0
    # the paper's figures keep its 1-based numbers, labelled as such
    fig2, ax = plt.subplots()
    plotting.plot_grain_profile(ax, rng.normal(size=50), interface=25, numbering="paper")
    assert ax.get_xlabel() == "grain number $i$ (paper's)"
    assert any(np.allclose(line.get_xdata(), 25.5) for line in ax.lines)
    assert ax.lines[0].get_xdata()[0] == 1
    plt.close(fig2)
    # the region numerals are placed in the regions theory assigns
    texts = sorted(t.get_text() for t in axes[1, 1].texts)
    assert texts == ["I", "II", "III", "IV"]
