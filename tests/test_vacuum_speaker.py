"""VacuumGripper and Speaker in the simulation (closed forms), and a .wbt world holding both.

tests/worlds/vacuum_speaker.yaml: the gripper's bounding cylinder (radius 0.05 m, 0.02 m tall) has
its bottom face 0.5 m above the robot's origin; the crate is a 0.4 m cube on the ground (top at
z = 0.4, sides at x, y = ±0.2) with physics. Lowering the robot by 0.1 m puts the gripper on the
crate. The presence reads whether a solid is held (Webots' ``mSolid != NULL``): a crate once touched
with the pump on is carried until the pump is off."""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys
import wave
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sensorium.server.sim.simulation import Simulation
from sensorium.server.sim.speaker import MAX_SOUNDS, speech_frames
from sensorium.server.sim.vacuum import GRIP_DISTANCE, _shape_obstacle, prism_gap
from sensorium.server.world import geometry as geo
from sensorium.server.world.geometry import Pose
from sensorium.server.world.loader import load_world

REPO = Path(__file__).resolve().parents[1]
WORLD = REPO / "tests" / "worlds" / "vacuum_speaker.yaml"
STEP = 16


@pytest.fixture
def sim() -> Simulation:
    return Simulation.from_file(WORLD)


def _presence_at(sim: Simulation, x: float, y: float, z: float) -> float:
    """The presence one measurement after the robot is put at (x, y, z), pump on, period one step."""
    g = sim.device("arm/gripper")
    g.set_on(True)          # type: ignore[attr-defined]
    g.enable(STEP)
    sim.robot("arm").set_pose(translation=[x, y, z])
    sim.step()
    return g.value          # type: ignore[attr-defined,no-any-return]


# ---------------------------------------------------------------------- VacuumGripper

def test_presence_on_the_crate_and_above_it(sim: Simulation) -> None:
    assert _presence_at(sim, 0.0, 0.0, 0.0) == 0.0            # 0.1 m above the crate
    assert _presence_at(sim, 0.0, 0.0, -0.1) == 1.0           # resting on its top: gap 0
    assert sim.device("arm/gripper").held == "crate"          # type: ignore[attr-defined]
    assert _presence_at(Simulation.from_file(WORLD), 0.0, 0.0, -0.15) == 1.0   # sunk 5 cm into it: overlap


@pytest.mark.parametrize("delta, held", [(-1e-9, 1.0), (1e-9, 0.0)])
def test_presence_either_side_of_the_contact_distance_above(sim: Simulation, delta: float, held: float) -> None:
    # the gripper's bottom is robot z + 0.5, the crate's top 0.4: the gap is z + 0.1
    assert _presence_at(sim, 0.0, 0.0, -0.1 + GRIP_DISTANCE + delta) == held


@pytest.mark.parametrize("delta, held", [(-1e-9, 1.0), (1e-9, 0.0)])
def test_presence_either_side_of_the_contact_distance_beside(sim: Simulation, delta: float, held: float) -> None:
    # lowered to z = -0.3 the gripper (z 0.2 .. 0.22) is level with the crate; beside its +x face
    # (x = 0.2) its edge is at x - 0.05: the gap is x - 0.25
    assert _presence_at(sim, 0.25 + GRIP_DISTANCE + delta, 0.0, -0.3) == held


def test_the_gap_to_a_corner_is_the_distance_between_the_prisms() -> None:
    """Past the crate's corner (0.2, 0.2) by (0.036, 0.048) and 0.5 mm above its top: the sections
    are 0.06 - 0.05 = 0.01 m apart, the heights 0.0005 m: √(0.01² + 0.0005²)."""
    crate = _shape_obstacle(geo.Box((0.4, 0.4, 0.4)), Pose(np.eye(3), [0.0, 0.0, 0.2]))
    cyl = _shape_obstacle(geo.Cylinder(0.05, 0.02), Pose(np.eye(3), [0.236, 0.248, 0.4105]))
    assert crate is not None and cyl is not None
    assert prism_gap(cyl, crate) == pytest.approx(math.hypot(0.01, 0.0005), rel=1e-12)
    floor = _shape_obstacle(geo.Plane(None), Pose.identity())
    assert floor is not None and prism_gap(cyl, floor) == pytest.approx(0.4005, rel=1e-12)


def test_presence_needs_the_pump_on(sim: Simulation) -> None:
    g = sim.device("arm/gripper")
    assert g.is_on is False                                  # type: ignore[attr-defined]   (isOn FALSE)
    g.enable(STEP)
    sim.robot("arm").set_pose(translation=[0.0, 0.0, -0.1])
    sim.step()
    assert g.value == 0.0                                    # type: ignore[attr-defined]   touching, off
    g.set_on(True)                                           # type: ignore[attr-defined]
    sim.step()
    assert g.value == 1.0                                    # type: ignore[attr-defined]
    g.set_on(False)                                          # type: ignore[attr-defined]
    sim.step()
    assert g.value == 0.0 and g.is_on is False               # type: ignore[attr-defined]
    g.set_on(True)                                           # type: ignore[attr-defined]
    sim.reset()                                              # Webots' reset: isOn as in the world file
    assert g.is_on is False                                  # type: ignore[attr-defined]
    sim.step()                                               # and the next presence value says so
    assert g.step_reading() == {"value": 0.0, "is_on": False}


def test_presence_is_sampled_at_its_period(sim: Simulation) -> None:
    """Enabled at 64 ms (4 basic steps) at t = 0: values at 64, 128, ... only; a hold that starts
    at 32 ms is first read at 64 ms, one that ends after 80 ms (the pump off) at 128 ms."""
    g = sim.device("arm/gripper")
    g.set_on(True)                                           # type: ignore[attr-defined]
    g.enable(64)
    got = []
    for k in range(1, 10):
        if k == 2:
            sim.robot("arm").set_pose(translation=[0.0, 0.0, -0.1])
        if k == 6:             # moving away would carry the crate along: the pump lets it go
            g.set_on(False)                                  # type: ignore[attr-defined]
        sim.step()
        got.append((sim.time_ms, g.value, g.measurements))   # type: ignore[attr-defined]
    assert got == [(16, 0.0, 0), (32, 0.0, 0), (48, 0.0, 0), (64, 1.0, 1), (80, 1.0, 1), (96, 1.0, 1),
                   (112, 1.0, 1), (128, 0.0, 2), (144, 0.0, 2)]


def test_a_gripper_without_a_bounding_shape_touches_nothing(sim: Simulation, tmp_path: Path) -> None:
    text = WORLD.read_text().replace("of_device: gripper, seen_by: bounding", "seen_by: visual")
    p = tmp_path / "w.yaml"
    p.write_text(text)
    s = Simulation.from_file(p)
    assert _presence_at(s, 0.0, 0.0, -0.1) == 0.0


# ---------------------------------------------------------------------- Speaker

def write_wav(path: Path, frames: int, rate: int, width: int = 2, channels: int = 1) -> Path:
    with wave.open(str(path), "wb") as w:
        w.setnchannels(channels)
        w.setsampwidth(width)
        w.setframerate(rate)
        w.writeframes(bytes(frames * width * channels))
    return path


def _playing_steps(sim: Simulation, limit: int = 10_000) -> int:
    """Steps until the speaker reports nothing playing (Webots' `while isSoundPlaying(): step()`)."""
    spk = sim.device("arm/speaker")
    n = 0
    while spk.playing or spk.speaking:                       # type: ignore[attr-defined]
        sim.step()
        n += 1
        assert n < limit
    return n


@pytest.mark.parametrize("frames, rate, pitch", [(3200, 32000, 1.0), (441, 44100, 1.0), (48000, 8000, 1.0),
                                                 (16000, 16000, 2.0), (1, 1000, 1.0), (0, 8000, 1.0)])
def test_a_sound_plays_for_the_steps_covering_its_length(sim: Simulation, frames: int, rate: int, pitch: float) -> None:
    """N frames at R frames/s and pitch p last N / (R p) s: the steps that cover them, ceil(1000 N /
    (R p) / 16), report it playing at their start, and the last of them ends it (at least one step)."""
    spk = sim.device("arm/speaker")
    spk.play_sound("s.wav", frames, rate, pitch, False, 0)   # type: ignore[attr-defined]
    assert spk.playing == ["s.wav"]                          # type: ignore[attr-defined]
    assert _playing_steps(sim) == max(1, math.ceil(1000 * frames / (rate * pitch) / STEP))


def test_a_looping_sound_plays_until_stopped_and_stop_ends_one(sim: Simulation) -> None:
    spk = sim.device("arm/speaker")
    spk.play_sound("loop.wav", 160, 16000, 1.0, True, 0)     # type: ignore[attr-defined]   10 ms, looping
    spk.play_sound("long.wav", 160000, 16000, 1.0, False, 0)  # type: ignore[attr-defined]   10 s
    sim.run(100)
    assert spk.playing == ["loop.wav", "long.wav"]           # type: ignore[attr-defined]
    spk.stop("loop.wav")                                     # type: ignore[attr-defined]
    assert spk.playing == ["long.wav"]                       # type: ignore[attr-defined]
    spk.stop("")                                             # type: ignore[attr-defined]   all
    assert spk.playing == [] and spk.active == 0.0           # type: ignore[attr-defined]


def test_playing_a_sound_again_while_it_plays_does_not_restart_it(sim: Simulation) -> None:
    spk = sim.device("arm/speaker")
    spk.play_sound("s.wav", 3200, 32000, 1.0, False, 0)      # type: ignore[attr-defined]   100 ms
    sim.run(3)                                               # 48 ms played
    spk.play_sound("s.wav", 3200, 32000, 1.0, False, 0)      # type: ignore[attr-defined]
    assert _playing_steps(sim) == 4                          # 52 ms left: 4 steps, not 7


def test_one_speaker_plays_at_most_max_sounds_at_once(sim: Simulation) -> None:
    """A bound on the work a controller can ask for: the 257th distinct sound playing at once is
    refused in one line (the same name again only updates it, as before); one stopped, another plays."""
    spk = sim.device("arm/speaker")
    for k in range(MAX_SOUNDS):
        spk.play_sound(f"s{k}.wav", 16000, 16000, 1.0, True, 0)   # type: ignore[attr-defined]
    spk.play_sound("s0.wav", 16000, 16000, 1.0, False, 0)          # type: ignore[attr-defined]   an update
    with pytest.raises(ValueError, match=f"{MAX_SOUNDS} sounds already play on this speaker"):
        spk.play_sound("one.wav", 16000, 16000, 1.0, False, 0)     # type: ignore[attr-defined]
    spk.stop("s1.wav")                                             # type: ignore[attr-defined]
    spk.play_sound("one.wav", 16000, 16000, 1.0, False, 0)         # type: ignore[attr-defined]
    assert len(spk.playing) == MAX_SOUNDS and spk.playing[-1] == "one.wav"   # type: ignore[attr-defined]


def test_speech_lasts_its_words(sim: Simulation) -> None:
    spk = sim.device("arm/speaker")
    text = "Hello <prosody rate='slow'>big</prosody> world"
    assert speech_frames(text) == 3
    spk.speak(text)                                          # type: ignore[attr-defined]
    assert spk.speaking                                      # type: ignore[attr-defined]
    assert _playing_steps(sim) == math.ceil(3 * 400 / STEP)  # 150 words a minute: 1.2 s
    spk.speak("one two")                                     # type: ignore[attr-defined]
    sim.run(10)
    spk.speak("one")                                         # type: ignore[attr-defined]   replaces it: 400 ms from now
    assert _playing_steps(sim) == 25


def test_reset_silences_the_speaker(sim: Simulation) -> None:
    spk = sim.device("arm/speaker")
    spk.play_sound("s.wav", 1, 1, 1.0, True, 0)              # type: ignore[attr-defined]
    sim.reset()
    assert spk.playing == [] and not spk.speaking            # type: ignore[attr-defined]


# ---------------------------------------------------------------------- .wbt

def test_a_wbt_with_a_vacuum_gripper_and_a_speaker_loads_them_simulated(tmp_path: Path) -> None:
    """Both are simulated: no "not simulated" line; the gripper's fields are read (isOn, the strengths)
    and its boundingObject is its own shape; WbVacuumGripper's resets for a bad strength and contactPoints."""
    p = tmp_path / "w.wbt"
    p.write_text('#VRML_SIM R2023b utf8\nRobot { name "r" children [\n'
                 'VacuumGripper { translation 0 0 0.5 name "cup" isOn TRUE tensileStrength 10 shearStrength -2 '
                 'contactPoints 0 boundingObject Cylinder { radius 0.05 height 0.02 } }\n'
                 'Speaker { name "voice" }\n] }\n'
                 'Solid { name "crate" translation 0 0 0.2 children [ Shape { geometry DEF B Box { size 0.4 0.4 0.4 } } ] '
                 'boundingObject USE B physics Physics { } }\n')
    w = load_world(p)
    assert not any("not simulated" in line for line in w.warnings), w.warnings
    assert [line.split(": ", 1)[1] for line in w.warnings] == [
        "VacuumGripper.shearStrength: -2 must be positive or -1 (infinite); using -1 (as Webots does)",
        "VacuumGripper.contactPoints: 0 is not > 0; using 3 (as Webots does)"]
    robot = w.world.robots[0]
    cup, voice = robot.devices
    assert (cup.device, cup.name, cup.is_on, cup.tensile_strength, cup.shear_strength, cup.contact_points) == \
        ("VacuumGripper", "cup", True, 10.0, -1.0, 3)
    assert (voice.device, voice.name) == ("Speaker", "voice")
    assert [s.of_device for s in robot.shapes] == ["cup"]
    assert w.world.solids[0].physics is True                 # its Physics node: what a gripper may carry
    sim = Simulation(w)
    g = sim.device("r/cup")
    g.enable(STEP)
    sim.step()
    assert g.value == 0.0                                    # type: ignore[attr-defined]   0.1 m above
    sim.robot("r").set_pose(translation=[0.0, 0.0, -0.1])
    sim.step()
    assert g.value == 1.0                                    # type: ignore[attr-defined]   on, on the crate
    assert [(e.name, e.simulated) for e in sim.robot("r").device_list] == [("cup", True), ("voice", True)]


def test_a_gripper_on_a_lift_joint_is_lowered_onto_the_crate(tmp_path: Path) -> None:
    """The gripper (its shape and the device ``on_joint: lift``) rides a LinearMotor moving down
    (axis -z): after each step the presence is 1 exactly when the lift's travel p leaves a gap
    0.1 - p of at most 1 mm (the lift moved kinematically, Webots' rule without physics)."""
    text = WORLD.read_text().replace(
        "of_device: gripper, seen_by: bounding}",
        "of_device: gripper, seen_by: bounding, on_joint: lift}").replace(
        "- {device: VacuumGripper, name: gripper, pose: {translation: [0.0, 0.0, 0.5]}}",
        "- {device: LinearMotor, name: lift, axis: [0, 0, -1], max_velocity: 0.05, max_force: 100.0, "
        "min_position: 0.0, max_position: 0.2}\n"
        "      - {device: VacuumGripper, name: gripper, pose: {translation: [0.0, 0.0, 0.5]}, on_joint: lift}")
    p = tmp_path / "lift.yaml"
    p.write_text(text)
    sim = Simulation.from_file(p)
    g, lift = sim.device("arm/gripper"), sim.robot("arm").motors["lift"]
    g.set_on(True)                                           # type: ignore[attr-defined]
    g.enable(STEP)
    lift.set_position(0.1)
    seen = set()
    for _ in range(250):                                     # 0.1 m at 0.05 m/s: 2 s, 125 steps and the ramp
        sim.step()
        travel = float(lift.position)
        assert g.value == (1.0 if 0.1 - travel <= GRIP_DISTANCE else 0.0), travel    # type: ignore[attr-defined]
        seen.add(g.value)                                    # type: ignore[attr-defined]
    assert seen == {0.0, 1.0} and float(lift.position) == pytest.approx(0.1)


@settings(max_examples=300, deadline=None, derandomize=True)
@given(st.text(alphabet="<> ab\t", max_size=40))
def test_markup_is_read_as_a_regular_expression_reads_it(text: str) -> None:
    """``<`` to the first ``>`` after it is markup (a space), a ``<`` with no ``>`` after it is text:
    what ``re.sub(r"<[^>]*>", " ", text)`` does, on short texts of those characters."""
    assert speech_frames(text) == len(re.sub(r"<[^>]*>", " ", text).split())


def test_a_megabyte_of_unclosed_markup_is_counted_at_once() -> None:
    """A text of 2**20 '<' and no '>' (the most a speak request carries) is two words after its
    'a b', counted in one pass: the regular expression it replaces took minutes here (quadratic),
    holding the server. Run in a child process with a generous limit (a few ms are expected)."""
    code = ("from sensorium.server.sim.speaker import speech_frames as f\n"
            "n = 1 << 20\n"
            "print(f('<' * n + 'a b'), f('<' * n + '> a b'), f('<a ' * (n // 3)))\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])})
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["2", "2", str((1 << 20) // 3)]


def test_a_gripper_touches_a_solid_as_a_supervisor_rebuilt_it(tmp_path: Path) -> None:
    """A top-level PROTO solid rebuilt under its name (a Supervisor set its size) is what the gripper
    touches from then on: the gripper kept each solid's shapes by name, so it went on touching the
    old, bigger box. The Obstacle (tests/protos/regen) is a box centred on its origin, here at z = 0.2;
    the gripper's bottom is 0.49 m above the robot's origin, lowered to z = -0.1."""
    import shutil

    from sensorium.server.daemon import supervisor as sv

    shutil.copy(REPO / "tests" / "protos" / "regen" / "Obstacle.proto", tmp_path / "Obstacle.proto")
    p = tmp_path / "w.wbt"
    p.write_text('#VRML_SIM R2023b utf8\nEXTERNPROTO "Obstacle.proto"\n'
                 'Robot { name "r" supervisor TRUE children [\n'
                 'VacuumGripper { translation 0 0 0.5 name "cup" isOn TRUE '
                 'boundingObject Cylinder { radius 0.05 height 0.02 } }\n] }\n'
                 'DEF BOX Obstacle { translation 0 0 0.2 size 0.4 0.4 0.4 }\n')
    sim = Simulation(load_world(p))
    g = sim.device("r/cup")
    g.enable(STEP)
    sim.robot("r").set_pose(translation=[0.0, 0.0, -0.1])
    sim.step()
    assert g.value == 1.0                          # type: ignore[attr-defined]   top at 0.4: gap -0.01
    assert sv.set_field(sim, sv.find_node(sim, "BOX"), "size", [0.2, 0.2, 0.2]) == []
    sim.step()
    assert g.value == 0.0                          # type: ignore[attr-defined]   top at 0.3: gap 0.09
    assert sv.set_field(sim, sv.find_node(sim, "BOX"), "size", [0.6, 0.6, 0.6]) == []
    sim.step()
    assert g.value == 1.0                          # type: ignore[attr-defined]   top at 0.5: sunk in it
