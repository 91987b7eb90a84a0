"""The joint seam, proven with the paper's Section 2 reading (S at the base, R at the
platform): it runs in both models, and both agree with each other for it as closely as for the
paper's equations (R at the base, S at the platform)."""
from __future__ import annotations

import numpy as np
import pytest

from runtime.cache import ResultCache
from studies.joint_orders import joint_order_study


@pytest.mark.slow
def test_both_joint_orders_agree_between_the_models(scene, tmp_path):
    study = joint_order_study(scene, scene.ci_cases, ResultCache(tmp_path))
    assert [c["case"] for c in study] == list(scene.ci_cases)
    for case in study:
        worst = {}
        for reading in case["readings"]:
            assert reading["error"] is None, reading["error"]
            # the FEM of either order states its own two-mesh error, GCI included
            assert reading["fem_estimated_error_percent"] == [
                max(e, g) for e, g in zip(reading["fem_estimated_error_percent"],
                                          reading["fem_gci_percent"])]
            assert 0 < max(reading["fem_gci_percent"]) < 0.5
            timo = np.abs(reading["models"]["Timoshenko, s=3"]["error_percent"])
            assert min(reading["models"]["Timoshenko, s=3"]["mac"]) > 0.99
            worst[(reading["base_joint"], reading["platform_joint"])] = timo.max()
        # Timoshenko s=3 against the 40-45 mm FEM: within 1 % in both orders (measured: 0.75 %
        # for R-S, 0.53 % for S-R at 32 mm), and the Section 2 order no worse than 1.5 times
        # the equations' order
        assert max(worst.values()) < 1.0
        assert worst[("S", "R")] < 1.5 * worst[("R", "S")]
