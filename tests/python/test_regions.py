"""Scenes, transform graphs and screen error regions from Python give exactly what
`covtrack regions SCENE --json` prints: the same code computes both."""
import json
import subprocess

import numpy as np
import pytest

import covtrack

SCENES = ["head_and_world", "sim_lab", "toolbox", "fixed_camera_tracked_tool"]


def cli_regions(covtrack_cli, scene, *options):
    run = subprocess.run([str(covtrack_cli), "regions", str(scene), "--json", *options],
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout)


def nan_for_null(values, shape):
    return np.array([np.full(shape, np.nan) if v is None else v for v in values], dtype=float)


def assert_same(py, cli):
    assert py.name == cli["name"] and py.frame == cli["frame"]
    assert py.valid == cli["valid"]
    assert py.flags == cli["flags"]
    if cli["assessment_px"] is None:
        assert np.isinf(py.assessment_px)
    else:
        assert py.assessment_px == cli["assessment_px"]
    vertices = cli["vertices"]
    np.testing.assert_array_equal(py.vertices_m, [v["vertex_m"] for v in vertices])
    np.testing.assert_array_equal(py.mean_px, nan_for_null([v["mean_px"] for v in vertices], 2))
    np.testing.assert_array_equal(py.covariance_px2, nan_for_null([v["covariance_px2"] for v in vertices], (2, 2)))
    np.testing.assert_array_equal(py.depth_m, [v["depth_m"] for v in vertices])
    assert py.vertex_flags == [v["flags"] for v in vertices]
    assert py.screen_hull == cli["screen_hull"]
    np.testing.assert_array_equal(py.outer_px, np.reshape(cli["outer_px"], (-1, 2)))
    np.testing.assert_array_equal(py.inner_px, np.reshape(cli["inner_px"], (-1, 2)))


@pytest.mark.parametrize("name", SCENES)
def test_shipped_scene_regions_equal_the_command(source_dir, covtrack_cli, name):
    path = source_dir / "config" / "scenes" / f"{name}.toml"
    cli = cli_regions(covtrack_cli, path)
    scene = covtrack.Scene(str(path))
    assert scene.camera_frame == cli["camera_frame"] and scene.confidence == cli["confidence"]
    regions = scene.regions()
    assert [r.name for r in regions] == scene.objects == [o["name"] for o in cli["objects"]]
    assert any(r.valid for r in regions)
    for py, c in zip(regions, cli["objects"]):
        assert_same(py, c)


def test_options_equal_the_commands_options(source_dir, covtrack_cli):
    path = source_dir / "config" / "scenes" / "head_and_world.toml"
    cli = cli_regions(covtrack_cli, path, "--method", "linear", "--propagation", "osgar-matrix16", "--confidence", "0.99")
    regions = covtrack.Scene(str(path), confidence=0.99).regions(method="linear", propagation="osgar-matrix16")
    for py, c in zip(regions, cli["objects"], strict=True):
        assert_same(py, c)


def test_graph_query_and_object_regions_give_the_scenes_regions(source_dir):
    scene = covtrack.Scene(str(source_dir / "config" / "scenes" / "head_and_world.toml"))
    t = 1_700_000_000_000_000
    graph = scene.graph(time_us=t)
    for r in scene.regions(graph=graph, time_us=t):
        T = graph.query(scene.camera_frame, r.frame, time_us=t)
        assert not T.unbounded and T.covariance.shape == (6, 6)
        again = covtrack.object_regions(scene.camera, T.matrix, T.covariance, r.vertices_m, scene.confidence)
        np.testing.assert_array_equal(again.outer_px, r.outer_px)
        assert again.assessment_px == r.assessment_px


def test_a_graph_by_hand_composes_and_tracks_staleness():
    graph = covtrack.TransformGraph()
    lift = np.eye(4)
    lift[2, 3] = 1.0
    graph.add_static("world", "table", lift, np.diag([1e-6] * 3 + [1e-8] * 3))
    graph.add_tracked("table", "tool", "arm", "tip", max_speed_mps=1.0)
    assert graph.query("world", "tool").unbounded  # not reported yet: LOST
    report = covtrack.Pose("arm", "tip", "table", "tool", [0.5, 0, 0], [1, 0, 0, 0], np.eye(6) * 1e-6, time_us=1_000_000)
    graph.update(report)
    fresh = graph.query("world", "tool", time_us=1_000_000)
    assert not fresh.unbounded
    np.testing.assert_allclose(fresh.position, [0.5, 0, 1.0])
    later = graph.query("world", "tool", time_us=2_000_000)  # 1 s old at 1 m/s: far wider
    assert later.covariance[0, 0] > 100 * fresh.covariance[0, 0]
    with pytest.raises(ValueError):
        graph.update(covtrack.Pose("other", "x", "table", "tool", [0, 0, 0], [1, 0, 0, 0]))
    with pytest.raises(ValueError, match="rigid"):
        graph.add_static("world", "skewed", np.diag([2.0, 1, 1, 1]))


def test_a_scene_with_a_mistake_names_it(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[camera]\nframe = "camera"\ncalibration = "nowhere.yml"\n[[transform]]\nparent = 3\n')
    with pytest.raises(ValueError, match="bad.toml"):
        covtrack.Scene(str(bad))
