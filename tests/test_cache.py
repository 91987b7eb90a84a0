"""The result cache: content keys, atomic entries, corrupt entries discarded and recomputed."""
from __future__ import annotations

import json

from runtime.cache import ResultCache, content_key


def test_same_inputs_same_key_and_different_inputs_different_key():
    assert content_key({"a": 1, "b": [1.0, 2.0]}) == content_key({"b": [1.0, 2.0], "a": 1})
    assert content_key({"a": 1}) != content_key({"a": 2})


def test_hit_after_compute_and_recompute_after_corruption(tmp_path):
    cache = ResultCache(tmp_path)
    calls = []

    def compute():
        calls.append(1)
        side = tmp_path / "side.bin"
        side.write_bytes(b"mode shapes")
        return {"frequencies_hz": [1.0, 2.0]}, {".vtu": side}

    value, key, hit = cache.get_or_compute("fem", {"x": 1}, compute, ("frequencies_hz",))
    assert not hit and value["frequencies_hz"] == [1.0, 2.0]
    value, key, hit = cache.get_or_compute("fem", {"x": 1}, compute, ("frequencies_hz",))
    assert hit and len(calls) == 1
    assert cache.side_file("fem", key, ".vtu").read_bytes() == b"mode shapes"

    entry = tmp_path / "fem" / f"{key}.json"
    entry.write_text(entry.read_text()[:10])  # truncated, as by a crash mid-write
    value, _, hit = cache.get_or_compute("fem", {"x": 1}, compute, ("frequencies_hz",))
    assert not hit and len(calls) == 2 and value["frequencies_hz"] == [1.0, 2.0]

    entry.write_text(json.dumps({"unexpected": True}))  # readable but wrong schema
    _, _, hit = cache.get_or_compute("fem", {"x": 1}, compute, ("frequencies_hz",))
    assert not hit and len(calls) == 3

    cache.side_file("fem", key, ".vtu").unlink()  # side file lost
    _, _, hit = cache.get_or_compute("fem", {"x": 1}, compute, ("frequencies_hz",))
    assert not hit and len(calls) == 4
    assert not list((tmp_path / "fem").glob(".*.tmp"))  # no temporary left behind


def test_key_follows_the_code_a_value_is_computed_with(monkeypatch, tmp_path):
    """A sweep task that pairs modes in pipeline/ is keyed on that code too: editing the
    pairing (or the model packages, common/ included) makes every such entry stale."""
    import runtime.cache as cache

    (tmp_path / "common").mkdir()
    (tmp_path / "common" / "a.py").write_text("x = 1\n")
    (tmp_path / "pipeline").mkdir()
    task = tmp_path / "pipeline" / "task.py"
    task.write_text("y = 1\n")
    monkeypatch.setattr(cache, "ROOT", tmp_path)
    monkeypatch.setattr(cache, "CODE_PACKAGES", ("common",))
    cache.code_fingerprint.cache_clear()
    plain, with_task = content_key({"a": 1}), content_key({"a": 1}, ("pipeline.task",))
    assert plain != with_task
    task.write_text("y = 2\n")
    cache.code_fingerprint.cache_clear()
    assert content_key({"a": 1}) == plain
    assert content_key({"a": 1}, ("pipeline.task",)) != with_task
    (tmp_path / "common" / "a.py").write_text("x = 2\n")
    cache.code_fingerprint.cache_clear()
    assert content_key({"a": 1}) != plain
    cache.code_fingerprint.cache_clear()


def test_the_model_packages_include_common():
    import runtime.cache as cache

    assert set(cache.CODE_PACKAGES) == {"analytical", "common", "joint_ends", "meshing",
                                        "fem_reference"}
