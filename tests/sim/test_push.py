"""Tests for pushjax.sim.push: the simulated MIT protocol, the recorded streams and the physics of each effect."""

import mujoco
import numpy as np
import pytest

from pushjax.geometry import get_object
from pushjax.mit import protocol
from pushjax.mit.files import PushParams
from pushjax.sim import push
from pushjax.sim.effects import Effects
from pushjax.sim.push import Simulator, simulate_push
from pushjax.sim.surfaces import PUSHER_OBJECT_FRICTION, SURFACES
from pushjax.sim.testbed import REALISTIC, draw_conditions


def params(shape="rect1", side=0, point=0.5, angle=0.0, velocity=20.0, acceleration=0.0, surface="abs"):
    return PushParams(surface=surface, shape=shape, acceleration=acceleration, velocity=velocity, side=side,
                      point=point, angle=angle)


def motion(recording):
    """Displacement (m, m) and rotation (rad) of the tracked frame over the recording."""
    pose = recording.true_object_pose
    return pose[-1, 1:3] - pose[0, 1:3], pose[-1, 3] - pose[0, 3]


def tip_in_object_frame(recording):
    pose, tip = recording.true_object_pose, recording.tip_pose
    cos, sin = np.cos(pose[:, 3]), np.sin(pose[:, 3])
    relative = tip[:, 1:3] - pose[:, 1:3]
    return np.stack([cos * relative[:, 0] + sin * relative[:, 1], -sin * relative[:, 0] + cos * relative[:, 1]], 1)


def stop_sample(p):
    return int(np.ceil(protocol.push_duration(p) * push.SAMPLE_RATE))


def test_recording_layout():
    p = params(velocity=50.0)
    recording = simulate_push(p)
    samples = int(np.ceil((protocol.push_duration(p) + push.POST_PUSH_DURATION) * 250)) + 1
    for stream in (recording.tip_pose, recording.object_pose, recording.ft_wrench):
        assert stream.shape == (samples, 4)
        np.testing.assert_allclose(stream[:, 0], np.arange(samples) / 250)
    assert np.all(recording.tip_pose[:, 3] == 0)
    tip_speed = np.linalg.norm(np.diff(recording.tip_pose[:, 1:3], axis=0), axis=1) * 250
    assert np.median(tip_speed[:stop_sample(p) - 2]) == pytest.approx(0.05, rel=1e-3)
    np.testing.assert_allclose(recording.object_pose, recording.true_object_pose)


def test_central_push_translates_with_the_pusher():
    """rect1 pushed through its centre along the normal at 20 mm/s: quasi-static, no rotation."""
    p = params()
    recording = simulate_push(p)
    displacement, rotation = motion(recording)
    direction = protocol.pusher_line("rect1", p)[1]
    assert displacement @ direction == pytest.approx(protocol.PUSH_DISTANCE, rel=0.05)
    assert abs(np.degrees(rotation)) < 1.0
    pushing = recording.ft_wrench[50:stop_sample(p) - 5]
    weight = get_object("rect1").mass * 9.81
    force_along = pushing[:, 1:3] @ direction
    assert np.median(force_along) == pytest.approx(SURFACES["abs"].object_friction * weight, rel=0.1)
    assert np.abs(pushing[:, 3]).max() < 1e-3
    # Quasi-static: the plate stops with the pusher.
    stop = stop_sample(p)
    assert np.linalg.norm(recording.true_object_pose[-1, 1:3] - recording.true_object_pose[stop, 1:3]) < 5e-4


def test_a_corner_push_along_the_next_face_is_not_flung():
    """rect3 pushed at the corner of side 1 at 0°: the pusher's line runs along side 0's face, a degenerate vertex
    contact that MuJoCo resolves along side 0's normal, flinging the plate ~5 cm sideways in 0.3 s; the push is
    simulated again with its line moved `CORNER_SHIFT` along the side and then moves like a corner push."""
    p = params(shape="rect3", side=1, point=1.0)
    recording = simulate_push(p)
    assert recording.line_shift == push.CORNER_SHIFT
    assert push.implausible_speed(recording.true_object_pose, p) is None
    displacement, rotation = motion(recording)
    direction = protocol.pusher_line("rect3", p)[1]
    assert displacement @ direction > 0.01 and abs(displacement @ [direction[1], -direction[0]]) < 0.01
    assert abs(np.degrees(rotation)) > 10.0
    assert simulate_push(params(shape="rect3", side=1, point=0.9)).line_shift == 0.0


def test_implausible_speed_bounds_the_object_by_the_pusher():
    p = params(velocity=20.0)
    times = np.arange(0.0, 1.0, 0.004)
    steady = np.column_stack([times, 0.02 * times, np.zeros_like(times), np.zeros_like(times)])
    assert push.implausible_speed(steady, p) is None
    flung = steady.copy()
    flung[times > 0.5, 1] += 0.03  # 3 cm in one sample
    gappy = np.delete(flung, np.s_[100:110], axis=0)  # dropped samples: the check goes by time stamps
    for pose in (flung, gappy):
        assert push.implausible_speed(pose, p) == pytest.approx(0.32, abs=0.01)
    assert push.implausible_speed(flung, params(velocity=150.0)) is None


def test_fast_push_slides_on_after_the_pusher_stops():
    p = params(velocity=300.0)
    recording = simulate_push(p)
    stop = stop_sample(p)
    sliding = recording.true_object_pose[-1, 1:3] - recording.true_object_pose[stop, 1:3]
    assert np.linalg.norm(sliding) > 0.01
    assert sliding @ protocol.pusher_line("rect1", p)[1] > 0
    assert np.all(recording.ft_wrench[stop + 5:, 1:] == 0)


def test_accelerating_push_ramps_up():
    p = params(velocity=500.0, acceleration=1000.0)
    recording = simulate_push(p)
    speed = np.linalg.norm(np.diff(recording.tip_pose[:, 1:3], axis=0), axis=1) * 250
    stop = stop_sample(p)
    np.testing.assert_allclose(speed[5:stop - 5], 1.0 * (np.arange(5, stop - 5) + 0.5) / 250, atol=2e-3)


def test_initial_pose_moves_the_whole_push():
    p = params("tri2", side=2, point=0.4, angle=-0.349)
    at_origin = simulate_push(p)
    pose = np.array([0.1, -0.05, 2.0])
    moved = simulate_push(p, initial_pose=pose)
    cos, sin = np.cos(pose[2]), np.sin(pose[2])
    rotation = np.array([[cos, -sin], [sin, cos]])
    np.testing.assert_allclose(moved.true_object_pose[:, 1:3],
                               pose[:2] + at_origin.true_object_pose[:, 1:3] @ rotation.T, atol=5e-4)
    np.testing.assert_allclose(np.unwrap(moved.true_object_pose[:, 3]),
                               np.unwrap(at_origin.true_object_pose[:, 3]) + pose[2], atol=0.01)
    np.testing.assert_allclose(moved.tip_pose[:, 1:3], pose[:2] + at_origin.tip_pose[:, 1:3] @ rotation.T, atol=5e-4)


def test_simulation_is_deterministic():
    p = params("butter", side=1, point=0.6, angle=0.349)
    first = simulate_push(p)
    simulate_push(params("butter", side=3, velocity=300.0))
    second = simulate_push(p)
    for name in ("tip_pose", "object_pose", "ft_wrench"):
        np.testing.assert_array_equal(getattr(first, name), getattr(second, name))


def test_bad_push_arguments():
    simulator = Simulator("rect1", "abs")
    with pytest.raises(ValueError, match="shape"):
        simulator.run(params("rect2"))
    with pytest.raises(ValueError, match="side"):
        simulator.run(params(side=4))
    with pytest.raises(ValueError, match="initial_pose"):
        simulator.run(params(), initial_pose=(0.0, 0.0))
    with pytest.raises(ValueError, match="rng"):
        Simulator("rect1", "abs", Effects(tracking_noise=(1e-3, 0.0))).run(params())


# Effects: each changes the motion the way physics says.

def test_com_offset_sets_the_rotation_of_a_central_push():
    # Pushing side 0 (x = +45 mm) towards -x: a centre of mass (and of support pressure) above the push line
    # turns the plate clockwise, below it counter-clockwise.
    _, above = motion(simulate_push(params(), Effects(com_offset=(0.0, 0.02))))
    _, below = motion(simulate_push(params(), Effects(com_offset=(0.0, -0.02))))
    assert np.degrees(above) < -10 and np.degrees(below) > 10


def test_rim_pressure_reduces_rotation():
    p = params(point=0.8)
    rotations = [abs(motion(simulate_push(p, Effects(pressure_rim=k)))[1]) for k in (-3.0, 0.0, 3.0)]
    assert rotations[0] > rotations[1] * 1.1 > rotations[2] * 1.2


def test_supports_farther_out_turn_the_plate_less():
    # The same off-centre push: a plate on its grid (distributed pressure) turns most, on a ring along its outline
    # less, on its four corners least (the limit surface's torque grows with the supports' distance).
    p = params(point=0.8)
    rotations = [abs(motion(simulate_push(p, support=support))[1]) for support in ("grid", "ring", "hull")]
    assert rotations[0] > rotations[1] * 1.1 > rotations[2] * 1.1


@pytest.mark.parametrize("surface", ["delrin", "pu"])
def test_the_pushing_force_moves_the_load_to_the_leading_edge(surface):
    # The pusher presses on the plate's side at half its thickness, the table's friction acts at its base: the
    # moment tips the load towards the side the plate slides to, by mu * thickness / 2 (moment balance), which
    # Lynch's planar model leaves out. Measured from the supports' normal forces while the plate slides.
    sim = Simulator("rect1", surface)
    centres, velocities = [], []

    def record(simulator):
        forces = simulator.support_normal_forces()
        centres.append(forces @ simulator.support_points / forces.sum())
        velocities.append(simulator.object_velocity())

    recording = sim.run(params(surface=surface), on_step=record)
    np.testing.assert_array_equal(recording.true_object_pose, simulate_push(params(surface=surface)).true_object_pose)
    centres, velocities = np.array(centres), np.array(velocities)
    sliding = velocities[:, 0] < -0.9 * params().velocity_si  # side 0 is pushed towards -x
    assert sliding.sum() > 100
    expected = SURFACES[surface].object_friction * get_object("rect1").thickness / 2
    assert np.median(-centres[sliding, 0]) == pytest.approx(expected, rel=0.2)
    assert np.median(np.abs(centres[sliding, 1])) < 0.1 * expected
    # Before the pusher reaches it, the plate rests on its supports' centre (its centre of mass).
    untouched = centres[:np.argmax(np.linalg.norm(velocities[:, :2], axis=1) > 1e-5)]
    assert len(untouched) > 10 and np.all(np.abs(untouched) < 0.05 * expected)


def test_sliding_supports_obey_coulombs_law_at_every_speed():
    # Each support of a turning plate slides at its own speed (fastest far from the centre of rotation); the table's
    # friction on it is mu times its normal force whatever that speed, as in the planar models: the soft contacts
    # regularise only below about half a millimetre per second (benchmarks/testbed_rate_dependence.py).
    sim = Simulator("rect1", "pu")
    ratios, speeds = [], []

    def record(simulator):
        forces, sliding = simulator.support_forces(), simulator.support_sliding_speeds()
        touching = forces[:, 0] > 0
        ratios.extend(forces[touching, 1] / forces[touching, 0])
        speeds.extend(sliding[touching])

    sim.run(params(surface="pu", point=0.2), on_step=record)
    ratios, speeds = np.array(ratios) / SURFACES["pu"].object_friction, np.array(speeds)
    slow, fast = (speeds > 1e-3) & (speeds < 8e-3), speeds > 15e-3
    assert slow.sum() > 100 and fast.sum() > 100
    for band in (slow, fast):
        assert np.median(ratios[band]) == pytest.approx(1.0, abs=0.02)
    np.testing.assert_allclose(sim.support_forces()[:, 0], sim.support_normal_forces())


def test_anisotropic_friction_turns_the_sliding_direction():
    """A slanted central push: the plate slides preferably along its low-friction axis."""
    p = params(angle=0.6)
    early = int(round((protocol.APPROACH_DISTANCE + 0.01) / 0.02 * 250))

    def sideways(anisotropy):
        pose = simulate_push(p, Effects(friction_anisotropy=anisotropy)).true_object_pose
        dx, dy = pose[early, 1:3] - pose[0, 1:3]
        return abs(dy / dx)

    assert sideways((1.0, 3.0)) < 0.5 * sideways((1.0, 1.0))


@pytest.mark.parametrize("anisotropy, steeper", [((1.0, 3.0), False), ((3.0, 1.0), True)])
def test_anisotropic_friction_bends_free_sliding_towards_the_slippery_axis(anisotropy, steeper):
    """A plate turned by 30° slides off diagonally in its own frame; friction turns it to the slippery axis."""
    simulator = Simulator("rect2", "abs", Effects(friction_anisotropy=anisotropy))
    model, data = simulator.model, simulator.data
    yaw = np.radians(30)
    mujoco.mj_resetData(model, data)
    data.qpos[:7] = [0, 0, simulator._settled_object[2], np.cos(yaw / 2), 0, 0, np.sin(yaw / 2)]
    data.qpos[7:9] = data.ctrl[:2] = [1.0, 1.0]
    heading = yaw + np.pi / 4
    data.qvel[:2] = 0.2 * np.array([np.cos(heading), np.sin(heading)])
    model.opt.timestep = 0.001
    mujoco.mj_step(model, data, nstep=300)
    assert np.linalg.norm(data.qvel[:2]) < 1e-3
    direction = np.arctan2(data.qpos[1], data.qpos[0]) - yaw  # in the object frame
    assert (direction > np.pi / 4 + 0.1) if steeper else (direction < np.pi / 4 - 0.1)


def test_pusher_friction_makes_the_contact_stick():
    p = params(angle=0.6)
    stop = stop_sample(p)

    def slip(mu):
        local = tip_in_object_frame(simulate_push(p, Effects(pusher_friction=mu)))
        return abs(local[stop, 1] - local[60, 1])

    slips = [slip(mu) for mu in (0.05, PUSHER_OBJECT_FRICTION, 0.8)]
    assert slips[0] > 2 * slips[1] and slips[1] > 1.5 * slips[2]


def test_tilted_table_pulls_the_pushed_object_downhill():
    level = motion(simulate_push(params()))[0]
    tilted = motion(simulate_push(params(), Effects(table_tilt_deg=2.0, table_tilt_azimuth_deg=90.0)))[0]
    assert tilted[1] - level[1] > 0.005


def test_tracking_effects_change_the_recorded_poses_only():
    p = params("tri1", side=1, point=0.3, angle=0.349)
    clean = simulate_push(p)
    bias = (0.002, -0.001, 0.05)
    biased = simulate_push(p, Effects(tracking_bias=bias))
    np.testing.assert_array_equal(biased.true_object_pose, clean.true_object_pose)
    np.testing.assert_array_equal(biased.tip_pose, clean.tip_pose)
    np.testing.assert_array_equal(biased.ft_wrench, clean.ft_wrench)
    yaw = clean.true_object_pose[:, 3]
    offset = np.stack([np.cos(yaw) * bias[0] - np.sin(yaw) * bias[1], np.sin(yaw) * bias[0] + np.cos(yaw) * bias[1]], 1)
    np.testing.assert_allclose(biased.object_pose[:, 1:3] - clean.true_object_pose[:, 1:3], offset, atol=1e-12)
    np.testing.assert_allclose(np.angle(np.exp(1j * (biased.object_pose[:, 3] - yaw))), bias[2], atol=1e-12)

    noisy = simulate_push(p, Effects(tracking_noise=(1e-3, 0.01)), rng=np.random.default_rng(3))
    np.testing.assert_array_equal(noisy.true_object_pose, clean.true_object_pose)
    error = noisy.object_pose[:, 1:] - clean.true_object_pose[:, 1:]
    error[:, 2] = np.angle(np.exp(1j * error[:, 2]))
    np.testing.assert_allclose(error.std(axis=0), [1e-3, 1e-3, 0.01], rtol=0.15)


def _episode_targets():
    """[250, 2] pusher positions of a 2 cm push into rect1's -x side along +x at 20 mm/s, from 5 mm away."""
    return np.column_stack([-0.045 - 0.00476 - 0.005 + 0.02 * np.arange(1, 251) / 250, np.zeros(250)])


def test_an_episode_in_pieces_is_the_episode_in_one():
    simulator = push.simulator("rect1", "abs")
    targets = _episode_targets()
    start = (-0.045 - 0.00476 - 0.005, 0.0)
    whole = push.Episode(simulator, (0.0, 0.0, 0.0), start, 0.04).advance(targets)
    episode = push.Episode(simulator, (0.0, 0.0, 0.0), start, 0.04)
    pieces = [episode.advance(targets[:100]), episode.advance(targets[100:])]
    assert episode.time == pytest.approx(1.0)
    np.testing.assert_array_equal(np.concatenate([p.true_object_pose for p in pieces]), whole.true_object_pose)
    assert whole.true_object_pose[-1, 1] > 0.01  # pushed about 1.5 cm
    np.testing.assert_allclose(whole.tip_pose[:, 1:3], targets, atol=2e-4)
    assert whole.ft_wrench[-1, 1] > 0.1  # the pusher pushes along +x
    conditions = draw_conditions(REALISTIC, 0, "rect1", "abs", (0, 1), len(simulator._support_pairs))
    tracked = push.Episode(simulator, (0.0, 0.0, 0.0), start, 0.04, conditions=conditions).advance(targets)
    noise = tracked.object_pose[:, 1:3] - tracked.true_object_pose[np.rint(tracked.object_pose[:, 0] * 250).astype(
        int) - 1, 1:3]
    assert 0 < np.abs(noise).max() < 6 * REALISTIC.tracking_noise_xy


def test_an_episode_refuses_moves_beyond_its_speed_limit():
    episode = push.Episode(push.simulator("rect1", "abs"), (0.0, 0.0, 0.0), (-0.1, 0.0), 0.02)
    with pytest.raises(ValueError, match="speed limit"):
        episode.advance(np.array([[-0.1 + 0.0001, 0.0]]))  # 25 mm/s
    with pytest.raises(ValueError, match="targets"):
        episode.advance(np.zeros((0, 2)))
    with pytest.raises(ValueError, match="speed_limit"):
        push.Episode(push.simulator("rect1", "abs"), (0.0, 0.0, 0.0), (-0.1, 0.0), 0.0)
