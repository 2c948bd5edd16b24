"""The supports' reactions from Python: summary["steps"][k]["support_reactions"] and the history's
<group>_reaction_x1/_x2/_x3 columns (the last ones), in equilibrium with the punch."""

import numpy as np

import stamp


def test_support_reactions_are_in_the_summary_and_the_history():
    p = stamp.Problem({
        "mesh": {"rectangle": {"x": [0.0, 20.0], "y": [0.0, 20.0], "n": [10, 10]}},
        "plate": {"thickness": 1.0, "E": 2.1e5, "nu": 0.3},
        "boundary": [{"group": "left", "fix": ["symmetry_x1"]},
                     {"group": "bottom", "fix": ["symmetry_x2"]},
                     {"group": "right", "fix": ["simply_supported"]},
                     {"group": "top", "fix": ["simply_supported"]},
                     {"group": "corner_ur", "fix": ["simply_supported"]}],
        "punch": [{"name": "sphere", "shape": "sphere", "radius": 50.0,
                   "center": [0.0, 0.0, 50.5], "motion": [0.0, 0.0, -0.5]}],
        "solver": {"steps": 2},
    }, name="py-reactions")
    r = p.solve(quiet=True)
    h = r.history
    groups = ["left", "bottom", "right", "top", "corner_ur"]
    assert list(h)[-15:] == [f"{g}_reaction_x{k}" for g in groups for k in (1, 2, 3)]
    for step, k in zip(r.summary["steps"], range(len(h["step"]))):
        s = step["support_reactions"]
        assert sorted(s) == sorted(groups)
        for g in groups:
            np.testing.assert_allclose([h[f"{g}_reaction_x{c}"][k] for c in (1, 2, 3)], s[g], rtol=1e-15, atol=0)
        # 'right' and 'top' hold v3 only, 'left' v1 only; the corner (20, 20) is held by 'right',
        # 'top' and 'corner_ur' and counted in each: less the corner twice, each dof counts once,
        # and the total balances the punch
        assert s["right"][:2] == [0.0, 0.0] and s["left"][1:] == [0.0, 0.0]
        total = np.sum([s[g] for g in groups], axis=0) - 2.0 * np.array(s["corner_ur"])
        np.testing.assert_allclose(total, step["support_reaction"], rtol=0, atol=1e-12 * abs(total[2]))
        np.testing.assert_allclose(total + np.array(step["reaction"]), 0.0, rtol=0, atol=1e-8 * abs(total[2]))
        assert total[2] > 0.0
