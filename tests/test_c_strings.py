"""The Python client passes strings as Webots' Python does: down to libController as C strings, which end
at their first NUL. A received packet's ``getString()`` keeps the sender's terminating NUL, and Webots
controllers hand such text on to setters; so every string argument that Webots' Python encodes into a C
string (``str.encode`` then ``char *``) is cut at its first NUL here too: each kind of setter given
"text\\0tail" does what it does given "text", against a real server in this process (our own world).
``Robot.getDevice`` looks a name up in Webots' Python dict and so is not cut; ``Emitter.send`` passes
bytes with their length and so is not cut either."""

from __future__ import annotations

import wave

import numpy as np
import pytest
from _inproc import inproc_server

from sensorium.client import wb
from sensorium.client.webots.controller import Camera, Robot, Supervisor

# the supervisor "boss" (a Display, a Speaker, a camera and a range finder looking at the textured wall
# WALL), the texture TEX whose url a Supervisor changes item by item, and CRATE, a PROTO instance whose
# body's shape is DEF LID
WORLD = """#VRML_SIM R2023b utf8
EXTERNPROTO "Crate.proto"
WorldInfo {
  basicTimeStep 16
}
Viewpoint {
  position 0 0 4
}
DEF WALL Solid {
  translation 1 0 0
  name "wall"
  children [
    Shape {
      appearance Appearance {
        texture DEF TEX ImageTexture {
          url [
            "a.png"
          ]
        }
      }
      geometry Box {
        size 0.1 1 1
      }
    }
  ]
}
DEF CRATE Crate {
  translation 0 2 0
}
DEF BOSS Robot {
  name "boss"
  controller "<extern>"
  supervisor TRUE
  children [
    Display {
      name "screen"
      width 48
      height 16
    }
    Speaker {
      name "speaker"
    }
    Camera {
      name "cam"
      width 4
      height 4
    }
    RangeFinder {
      name "depth"
      width 4
      height 4
    }
  ]
}
"""


CRATE = """#VRML_SIM R2023b utf8
PROTO Crate [
  field SFVec3f translation 0 0 0
]
{
  Solid {
    translation IS translation
    name "crate"
    children [
      DEF LID Shape {
        geometry Box {
          size 0.2 0.2 0.2
        }
      }
    ]
  }
}
"""


@pytest.fixture
def served(tmp_path, monkeypatch):
    """The world in tmp_path (its images a.png and b.png, a WAV), served in this process; the client attached
    to "boss", run from tmp_path (the folder a controller's relative file names start from)."""
    from PIL import Image

    (tmp_path / "w.wbt").write_text(WORLD)
    (tmp_path / "Crate.proto").write_text(CRATE)
    Image.new("RGB", (2, 2), (200, 100, 30)).save(tmp_path / "a.png")
    Image.new("RGB", (2, 2), (30, 100, 200)).save(tmp_path / "b.png")
    with wave.open(str(tmp_path / "tone.wav"), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(8000)
        w.writeframes(b"\0\0" * 8000)                 # one second
    monkeypatch.chdir(tmp_path)
    with inproc_server(heartbeat_ms=5000, world=tmp_path / "w.wbt") as (core, transport):
        wb.wb_robot_init(f"{transport.rpc_endpoint}/boss")
        try:
            yield core
        finally:
            wb.wb_robot_cleanup()
            Robot.created = None                     # (Supervisor() sets it on Robot)


def test_the_helper_cuts_a_str_at_its_first_nul_and_leaves_anything_else() -> None:
    assert wb.c_string("08-Dec-2026 00:00:07\0") == "08-Dec-2026 00:00:07"
    assert wb.c_string("a\0b\0c") == "a" and wb.c_string("\0a") == "" and wb.c_string("plain") == "plain"
    assert wb.c_string(None) is None and wb.c_string(b"a\0b") == b"a\0b" and wb.c_string(3) == 3


def test_node_and_field_lookups_and_string_fields_read_up_to_the_nul(served, capsys) -> None:
    wall = wb.wb_supervisor_node_get_from_def("WALL")
    assert wall is not None and wb.wb_supervisor_node_get_from_def("WALL\0tail") == wall
    boss = wb.wb_supervisor_node_get_from_def("BOSS")
    custom = wb.wb_supervisor_node_get_field(boss, "customData\0tail")
    assert custom is not None and custom == wb.wb_supervisor_node_get_field(boss, "customData")
    assert wb.wb_supervisor_node_get_base_node_field(boss, "customData\0") is not None
    crate = wb.wb_supervisor_node_get_from_def("CRATE")
    lid = wb.wb_supervisor_node_get_from_proto_def(crate, "LID")
    assert lid is not None and wb.wb_supervisor_node_get_from_proto_def(crate, "LID\0tail") == lid
    wb.wb_supervisor_field_set_sf_string(custom, "gain=2\0stale bytes")
    assert wb.wb_supervisor_field_get_sf_string(custom) == "gain=2"
    wb.wb_robot_step(16)          # (a set the same step would yield to the Supervisor's: test_custom_data_timing)
    wb.wb_robot_set_custom_data("gain=3\0")
    assert wb.wb_robot_get_custom_data() == "gain=3" == served.sim.robots["boss"].custom_data

    tex = wb.wb_supervisor_node_get_from_def("TEX")
    url = wb.wb_supervisor_node_get_field(tex, "url")
    wb.wb_supervisor_field_set_mf_string(url, 0, "b.png\0.png")
    wb.wb_supervisor_field_insert_mf_string(url, -1, "a.png\0")
    assert [wb.wb_supervisor_field_get_mf_string(url, i) for i in range(wb.wb_supervisor_field_get_count(url))] \
        == ["b.png", "a.png"]

    root = wb.wb_supervisor_node_get_root()
    children = wb.wb_supervisor_node_get_field(root, "children")
    wb.wb_supervisor_field_import_mf_node_from_string(children, -1, 'DEF NEW Solid { name "new" }\0 }}} unread')
    new = wb.wb_supervisor_node_get_from_def("NEW")
    assert new is not None and wb.wb_supervisor_field_get_sf_string(wb.wb_supervisor_node_get_field(new, "name")) \
        == "new"
    assert capsys.readouterr().err == ""


def test_a_state_saved_under_a_name_with_a_tail_loads_under_the_name(served, capsys) -> None:
    boss = wb.wb_supervisor_node_get_from_def("BOSS")
    translation = wb.wb_supervisor_node_get_field(boss, "translation")
    wb.wb_supervisor_node_save_state(boss, "start\0x")
    wb.wb_supervisor_field_set_sf_vec3f(translation, [0.5, 0.25, 0.0])
    wb.wb_robot_step(16)
    wb.wb_supervisor_node_load_state(boss, "start")
    wb.wb_robot_step(16)
    assert wb.wb_supervisor_field_get_sf_vec3f(translation) == [0.0, 0.0, 0.0]
    assert capsys.readouterr().err == ""


def test_display_text_and_font_are_what_is_before_the_nul(served, capsys) -> None:
    """Text and a font name taken from a fixed-size, NUL-padded buffer (a packet's field, Python's
    ``struct.unpack("1100s")``): the text "hi" is drawn (its padding is over the server's 1024
    characters), the font name fits, and a text that is only padding is Webots' "NULL or empty" line."""
    screen = wb.wb_robot_get_device("screen")
    pixels = served.sim.device("boss/screen").pixels

    def drawn(font: str, text: str) -> np.ndarray:
        wb.wb_display_set_color(screen, 0x000000)
        wb.wb_display_fill_rectangle(screen, 0, 0, 48, 16)
        wb.wb_display_set_color(screen, 0xFFFFFF)
        wb.wb_display_set_font(screen, font, 8, False)
        wb.wb_display_draw_text(screen, text, 1, 1)
        wb.wb_robot_step(16)
        return pixels.copy()

    plain = drawn("Lucida Console", "hi")
    assert (plain != plain[0, -1]).any()             # some text was drawn
    assert (drawn("Lucida Console".ljust(300, "\0"), "hi".ljust(1100, "\0")) == plain).all()
    assert capsys.readouterr().err == ""
    assert (drawn("Lucida Console", "\0" * 8) == plain[0, -1]).all()     # nothing drawn
    assert capsys.readouterr().err == "Error: wb_display_draw_text(): 'text' argument is NULL or empty.\n"


def test_file_names_are_written_up_to_the_nul(served, tmp_path) -> None:
    cam = wb.wb_robot_get_device("cam")
    wb.wb_camera_enable(cam, 16)
    wb.wb_robot_step(16)
    assert wb.wb_camera_save_image(cam, "cam.png\0.jpg", 100) == 0
    depth = wb.wb_robot_get_device("depth")
    wb.wb_range_finder_enable(depth, 16)
    wb.wb_robot_step(16)
    assert wb.wb_range_finder_save_image(depth, "depth.png\0.hdr", 100) == 0
    screen = wb.wb_robot_get_device("screen")
    wb.wb_display_image_save(screen, None, "screen.png\0tail")
    assert wb.wb_display_image_load(screen, "screen.png\0tail") is not None
    wb.wb_supervisor_export_image("view.png\0tail", 100)
    assert wb.wb_supervisor_world_save("saved.wbt\0tail")
    written = sorted(p.name for p in tmp_path.iterdir())
    assert written == ["Crate.proto", "a.png", "b.png", "cam.png", "depth.png", "saved.wbt", "screen.png", "tone.wav",
                       "view.png", "w.wbt"]


def test_the_speaker_plays_and_speaks_what_is_before_the_nul(served, tmp_path, capsys) -> None:
    speaker = wb.wb_robot_get_device("speaker")
    assert wb.wb_speaker_set_engine(speaker, "pico\0tail") and wb.wb_speaker_set_language(speaker, "en-US\0")
    wb.wb_speaker_play_sound(speaker, speaker, "tone.wav\0tail", 1.0, 1.0, 0.0, False)
    wb.wb_robot_step(16)
    assert wb.wb_speaker_is_sound_playing(speaker, "tone.wav\0") and wb.wb_speaker_is_sound_playing(speaker, "tone.wav")
    wb.wb_speaker_stop(speaker, "tone.wav\0tail")
    wb.wb_robot_step(16)
    assert not wb.wb_speaker_is_sound_playing(speaker, "tone.wav")
    # speech lasts 0.4 s a word: "hello" alone is over after 25 steps of 16 ms, not the three words after the NUL
    wb.wb_speaker_speak(speaker, "hello\0 big world", 1.0)
    steps = 0
    while True:
        wb.wb_robot_step(16)
        steps += 1
        if not wb.wb_speaker_is_speaking(speaker) or steps > 100:
            break
    assert steps == 25
    assert capsys.readouterr().err == ""


def test_the_webots_classes_cut_where_webots_python_encodes_and_get_device_does_not(served, capsys) -> None:
    sup = Supervisor()
    assert sup.getFromDef("WALL\0tail") == sup.getFromDef("WALL") is not None
    assert Camera("cam\0tail").getName() == "cam"       # Device(name): wb_robot_get_device(str.encode(name))
    assert sup.getDevice("cam\0tail") is None           # Webots' Python looks the name up in a dict
    assert 'Device "cam\0tail" was not found' in capsys.readouterr().err
    custom = sup.getFromDef("BOSS").getField("customData\0")
    custom.setSFString("mode=1\0tail")
    assert custom.getSFString() == "mode=1"
    custom.value = "mode=2\0tail"
    assert custom.value == "mode=2"
    sup.step(16)                  # (a set the same step would yield to the Supervisor's: test_custom_data_timing)
    sup.setCustomData("mode=3\0tail")
    assert sup.getCustomData() == "mode=3" == custom.getSFString()
    assert sup.getUrdf("p_\0tail") == sup.getUrdf("p_")


def test_a_motion_file_and_a_movie_are_named_up_to_the_nul(served, tmp_path, capsys) -> None:
    import shutil

    from sensorium.client import wb_movie

    (tmp_path / "still.motion").write_text("#WEBOTS_MOTION,V1.0,cam\n00:00:000,Pose1,*\n00:01:000,Pose2,*\n")
    motion = wb.wbu_motion_new("still.motion\0tail")
    assert motion is not None and wb.wbu_motion_get_duration(motion) == 1000
    assert "ignoring 'cam' of file 'still.motion': it is a Camera" in capsys.readouterr().err
    if shutil.which("ffmpeg") is None:
        return
    wb.wb_supervisor_movie_start_recording("film.mp4\0.avi", 160, 120, 0, 90, 1, False)
    for _ in range(4):
        wb.wb_robot_step(16)
    wb.wb_supervisor_movie_stop_recording()
    wb_movie.recorder(wb.current()).poll(wait=120)   # ffmpeg's end waited for (a loaded machine takes seconds)
    assert wb.wb_supervisor_movie_is_ready()
    assert not wb.wb_supervisor_movie_failed() and (tmp_path / "film.mp4").is_file(), capsys.readouterr().err
    assert capsys.readouterr().err == ""
