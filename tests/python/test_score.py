"""epichead.score_poses: the C++ scorer of `epichead score` on the teabox's ViSP reference."""
import json
import math
import subprocess

import pytest

import epichead


def reference(teabox_dir):
    return epichead.read_pose_csv(str(teabox_dir / "reference_visp.csv"))


def test_poses_scored_against_themselves_are_exact(teabox, teabox_dir):
    ref = reference(teabox_dir)
    s = epichead.score_poses(ref, ref, teabox.camera, teabox.model)
    assert s.frames == len(ref) and s.present == len(ref) and s.succeeded == len(ref)
    assert s.success_rate == 1.0 and s.success_rate_2cm_2deg == 1.0 and s.losses == 0
    assert s.rotation_deg.p95 < 1e-5 and s.translation_mm.p95 < 1e-6
    assert len(s.per_frame) == len(ref)


def test_a_shift_is_measured_in_millimetres_and_fails_beyond_5_cm(teabox, teabox_dir):
    ref = reference(teabox_dir)[:10]
    shifted = []
    for i, p in enumerate(ref):
        pose = p.pose.copy()
        pose[0, 3] += 0.03 if i < 5 else 0.06
        shifted.append(epichead.StampedPose(p.frame, p.t_s, pose, "tracked"))
    s = epichead.score_poses(ref, shifted, teabox.camera, teabox.model)
    assert [f.translation_mm for f in s.per_frame] == [approx(30)] * 5 + [approx(60)] * 5
    assert [f.success for f in s.per_frame] == [True] * 5 + [False] * 5
    assert [f.success_2cm_2deg for f in s.per_frame] == [False] * 10
    assert s.success_rate == 0.5 and s.losses == 1


def test_lost_and_missing_frames_fail(teabox, teabox_dir):
    ref = reference(teabox_dir)[:6]
    est = [epichead.StampedPose(p.frame, p.t_s, p.pose, "lost" if p.frame == 2 else "tracked") for p in ref if p.frame != 4]
    s = epichead.score_poses(ref, est, teabox.camera, teabox.model)
    assert [f.success for f in s.per_frame] == [True, True, False, True, False, True]
    assert s.present == 4 and s.losses == 2
    assert math.isnan(s.per_frame[4].rotation_deg)


def test_the_same_summary_as_the_score_command(teabox, teabox_dir, tmp_path, program):
    ref = reference(teabox_dir)[:20]
    est = []
    for p in ref:
        pose = p.pose.copy()
        pose[:3, 3] += [0.004, -0.002, 0.01]
        est.append(epichead.StampedPose(p.frame, p.t_s, pose, "tracked"))
    path = tmp_path / "poses.csv"
    epichead.write_pose_csv(str(path), est)
    ref_path = tmp_path / "ref.csv"
    epichead.write_pose_csv(str(ref_path), ref)
    out = subprocess.run([program, "score", str(teabox_dir), str(path), "--reference", str(ref_path), "--json"],
                         check=True, capture_output=True, text=True).stdout
    cli = json.loads(out)
    s = epichead.score_poses(epichead.read_pose_csv(str(ref_path)), epichead.read_pose_csv(str(path)),
                             teabox.camera, teabox.model)
    assert cli["frames"] == s.frames and cli["succeeded"] == s.succeeded and cli["losses"] == s.losses
    for key in ("rotation_deg", "translation_mm", "reprojection_px"):
        for stat in ("mean", "median", "p95"):
            assert cli[key][stat] == approx(getattr(getattr(s, key), stat))


def approx(v):
    return pytest.approx(v, rel=1e-6, abs=1e-6)
