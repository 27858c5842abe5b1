"""epichead.Tracker and epichead.Predictor on the first frames of the real teabox video."""
import numpy as np
import pytest

import epichead

FRAMES = 5


def track_frames(seq, tracker, frames=FRAMES, grey=False):
    pose = seq.init.pose
    results = []
    for i in range(frames):
        image = seq.read_frame(i)
        if grey:
            image = image.mean(axis=2).astype(np.uint8)
        r = tracker.track(image, pose)
        if r.status != "lost":
            pose = r.pose
        results.append(r)
    return results


def test_tracks_the_teabox_from_its_init_pose(teabox):
    tracker = epichead.Tracker(teabox.camera, teabox.model)
    assert tracker.mode == "epic+validation"
    results = track_frames(teabox, tracker)
    assert [r.status for r in results] == ["tracked"] * FRAMES
    r = results[-1]
    assert r.pose.shape == (4, 4) and r.covariance.shape == (6, 6)
    np.testing.assert_allclose(r.covariance, r.covariance.T, atol=1e-12)
    assert np.all(np.linalg.eigvalsh(r.covariance) > 0)
    assert r.visible >= 4 and r.inliers >= 4 and r.reasons == ""
    assert r.times_ms["total"] > 0


def test_a_start_frame_says_which_start_it_kept(teabox):
    tracker = epichead.Tracker(teabox.camera, teabox.model)
    first, second = track_frames(teabox, tracker, frames=2)
    assert first.start["kept"] in ("given", "gradient_pass")
    given, gradient = first.start["support_given"], first.start["support_gradient_pass"]
    if first.start["kept"] == "gradient_pass":
        assert gradient is not None and (given is None or gradient >= given)
    assert second.start is None  # tracked on from the first frame: no start


def test_per_edge_results_name_model_edges_and_chosen_lines(teabox):
    tracker = epichead.Tracker(teabox.camera, teabox.model)
    r = track_frames(teabox, tracker, frames=1)[0]
    assert len(r.lines) == r.visible
    edges = teabox.model.edges
    kept = [l for l in r.lines if l.inlier]
    assert len(kept) == r.inliers
    for l in r.lines:
        assert 0 <= l.edge < len(edges)
        assert l.found or not l.inlier
    # A kept line lies on its model edge projected at the estimated pose.
    verts = teabox.model.vertices
    for l in kept:
        a, b = verts[edges[l.edge][0]], verts[edges[l.edge][1]]
        cam = (r.pose[:3, :3] @ np.stack([a, b]).T).T + r.pose[:3, 3]
        pa, pb = teabox.camera.project(cam)
        d = pb - pa
        normal = np.array([-d[1], d[0]]) / np.linalg.norm(d)
        # Its middle within a few pixels (the window's ends may tilt a little further off).
        assert abs(np.dot((l.a_px + l.b_px) / 2 - pa, normal)) < 3.0
        for p in (l.a_px, l.b_px):
            assert abs(np.dot(p - pa, normal)) < 8.0


def test_tracks_grey_images_too(teabox):
    tracker = epichead.Tracker(teabox.camera, teabox.model, mode="epic")
    results = track_frames(teabox, tracker, frames=3, grey=True)
    assert all(r.status != "lost" for r in results)


def test_poses_agree_with_the_visp_reference(teabox, teabox_dir):
    tracker = epichead.Tracker(teabox.camera, teabox.model)
    results = track_frames(teabox, tracker)
    estimates = [epichead.StampedPose(f.frame, f.t_s, r.pose, r.status) for f, r in zip(teabox.frames, results)]
    reference = [p for p in epichead.read_pose_csv(str(teabox_dir / "reference_visp.csv")) if p.frame < FRAMES]
    score = epichead.score_poses(reference, estimates, teabox.camera, teabox.model)
    assert score.frames == FRAMES and score.success_rate == 1.0
    assert score.reprojection_px.median < 3.0


def test_tracks_from_the_constant_velocity_prediction(teabox):
    tracker = epichead.Tracker(teabox.camera, teabox.model)
    predictor = epichead.Predictor(mode="constant_velocity")
    assert predictor.predict(0.0) is None
    pose = teabox.init.pose
    for i in range(FRAMES):
        t = teabox.frames[i].t_s
        prediction = predictor.predict(t)
        start = pose if prediction is None else prediction.pose
        r = tracker.track(teabox.read_frame(i), start)
        assert r.status == "tracked"
        verdict, _ = predictor.add_vision(t, r.pose, r.covariance)
        assert verdict in ("applied", "initialised")
        pose = r.pose
    status = predictor.status(teabox.frames[FRAMES - 1].t_s)
    assert status["initialised"] and status["counters"]["vision_applied"] == FRAMES - 1


def test_imu_predictor_propagates_a_turn():
    # At rest for 0.2 s, then a pose, then 0.1 s turning at 1 rad/s about the camera's y axis.
    p = epichead.Predictor(mode="imu")
    g = np.array([0.0, -9.81, 0.0])  # specific force at rest, y down
    for k in range(200):
        p.add_imu(k * 0.001, np.zeros(3), g)
    pose = np.eye(4)
    pose[2, 3] = 1.0
    verdict, _ = p.add_vision(0.199, pose, np.eye(6) * 1e-6)
    assert verdict == "initialised"
    for k in range(200, 300):
        assert p.add_imu(k * 0.001, np.array([0.0, 1.0, 0.0]), g) == "accepted"
    pred = p.predict(0.299)
    assert pred is not None and pred.covariance.shape == (6, 6)
    # The camera turned by about 0.1 rad: the object's direction in the camera turned by as much.
    angle = np.arccos(np.clip((np.trace(pred.pose[:3, :3]) - 1) / 2, -1, 1))
    assert angle == pytest.approx(0.1, abs=0.01)
    assert p.status(0.299)["counters"]["imu_accepted"] >= 100


def test_an_uncertain_clock_offset_weighs_a_pose_taken_mid_turn_less():
    # The same late pose (where the camera was 10 ms earlier, turning at 1 rad/s) is further from
    # the prediction, in Mahalanobis terms, when the offset is told exact than when it may be
    # 10 ms off.
    def run(sigma_s):
        p = epichead.Predictor(mode="imu", imu_time_offset_sigma_s=sigma_s)
        g = np.array([0.0, -9.81, 0.0])
        for k in range(200):
            p.add_imu(k * 0.001, np.zeros(3), g)
        pose = np.eye(4)
        pose[2, 3] = 1.0
        assert p.add_vision(0.199, pose, np.eye(6) * 1e-6)[0] == "initialised"
        for k in range(200, 320):
            p.add_imu(k * 0.001, np.array([0.0, 1.0, 0.0]), g)
        late = p.predict(0.289).pose
        verdict, d2 = p.add_vision(0.299, late, np.eye(6) * 1e-6)
        return d2

    assert run(0.01) < 0.5 * run(0.0)
    with pytest.raises(epichead.Error, match="imu_time_offset_sigma_s"):
        epichead.Predictor(imu_time_offset_sigma_s=-1.0)
