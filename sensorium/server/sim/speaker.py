"""The simulation's Speaker (Webots' WbSpeaker, headless: no audio is produced).

What it keeps is what a controller can observe: which sounds are playing and whether it speaks.
Webots plays a sound through OpenAL and tells the controller when it is over (``C_SPEAKER_SOUND_OVER``
with a step answer); here a sound plays in simulated time. The client reads the WAV file (its
frames N and rate R: the controller's files are the controller's) and the server counts the sound's
progress in frames, exactly (fractions): each basic step of ``dt`` ms advances it by
``dt · R · pitch / 1000`` frames (OpenAL's pitch resamples, so it changes the speed; a pitch of 0,
which OpenAL refuses, keeps 1). A sound is over after the first step whose end reaches its N frames:
a sound of N/R s started at t0 reads playing after every step ending before t0 + N/R, so a controller
looping ``while isSoundPlaying(): step()`` steps ceil(N/R / dt) times. A looping sound plays until
``stop``. Playing a sound again while it plays only changes its loop and pitch (WbSpeaker::playSound
restarts a sound that is over, not one that plays).

Text to speech (``speak``): there is no synthesiser, so a text lasts :data:`SECONDS_PER_WORD` per
word (150 words a minute), its words the whitespace-separated runs outside ``<...>`` markup; a new
text replaces the one being spoken, as WbSpeaker::playText stops the previous one.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from sensorium.server.sim.sensors import Device

__all__ = ["SECONDS_PER_WORD", "Speaker", "speech_frames"]

SECONDS_PER_WORD = Fraction(2, 5)
"""s per spoken word (150 words a minute)."""

MAX_SOUNDS = 256
"""Sounds one speaker plays at once (a bound of ours: each costs the server work every step)."""


def _without_markup(text: str) -> str:
    """``text`` with each ``<...>`` (from a ``<`` to the first ``>`` after it) made a space, in one
    pass: the regular expression ``<[^>]*>`` took quadratic time on a text of many ``<`` and no ``>``
    (a megabyte of them held the server for minutes). A ``<`` with no ``>`` after it is text."""
    out: list[str] = []
    i = 0
    while True:
        j = text.find("<", i)
        k = -1 if j < 0 else text.find(">", j + 1)
        if k < 0:
            out.append(text[i:])
            return "".join(out)
        out.append(text[i:j])
        out.append(" ")
        i = k + 1


def speech_frames(text: str) -> int:
    """The words of a text to speak (its duration is that times :data:`SECONDS_PER_WORD`)."""
    return len(_without_markup(text).split())


@dataclass(slots=True)
class _Sound:
    name: str                        # the sound's file name, as the controller gave it
    frames: int                      # its length, in frames
    rate: int                        # frames per second at pitch 1
    pitch: Fraction
    loop: bool
    done: Fraction = Fraction(0)     # frames played so far

    def advance(self, dt_ms: int) -> bool:
        """Play ``dt_ms`` more; True while it is still playing after them."""
        self.done += Fraction(dt_ms * self.rate, 1000) * self.pitch
        return self.loop or self.done < self.frames


class Speaker(Device):
    """One speaker: the sounds playing (by key: the file name, with ``_left``/``_right`` for one
    side of a stereo pair, as WbSpeaker keys them) and the text being spoken. Every change (a sound
    started, over or stopped; speech started or over) counts as a measurement: the step reply of a
    controller carries the new state (``step_reading``)."""

    reports_unasked = True          # its state goes with step replies without an enable (daemon/services.py)

    def __post_init__(self) -> None:
        super().__post_init__()
        self.sounds: dict[str, _Sound] = {}
        self.speech: _Sound | None = None

    # -- controller API
    def play_sound(self, sound: str, frames: int, rate: int, pitch: float, loop: bool, side: int) -> None:
        """``wb_speaker_play_sound`` on this speaker (libController's side: 0 both, -1 left, 1 right)."""
        if not sound:
            raise ValueError("the sound's file name is empty")
        if frames < 0 or rate <= 0:
            raise ValueError(f"a sound of {frames} frames at {rate} frames/s")
        key = sound + {0: "", -1: "_left", 1: "_right"}[side]
        p = Fraction(pitch) if pitch > 0.0 else Fraction(1)
        playing = self.sounds.get(key)
        if playing is not None:                   # still playing: WbSpeaker only updates it
            playing.loop, playing.pitch = bool(loop), p
        elif len(self.sounds) >= MAX_SOUNDS:
            raise ValueError(f"{MAX_SOUNDS} sounds already play on this speaker (the server's bound): stop one first")
        else:
            self.sounds[key] = _Sound(sound, int(frames), int(rate), p, bool(loop))
        self._mark(self.clock())

    def stop(self, sound: str) -> None:
        """``wb_speaker_stop``: that sound (either side), or with "" every sound and the speech."""
        if not sound:
            self.sounds.clear()
            self.speech = None
        else:
            for key in (sound, sound + "_left", sound + "_right"):
                if self.sounds.pop(key, None) is not None:
                    break                         # WbSpeaker::stop takes the first key it finds
        self._mark(self.clock())

    def speak(self, text: str) -> None:
        """``wb_speaker_speak``: the text replaces the one being spoken (no synthesiser: see the module)."""
        words = speech_frames(text)
        per_word = SECONDS_PER_WORD * 1000                # ms per word: a "sound" of 1 frame per ms
        self.speech = _Sound("", int(words * per_word), 1000, Fraction(1), False)
        self._mark(self.clock())

    # -- the simulation's step
    def advance(self, dt_ms: int, now_ms: int) -> None:
        """One basic step of ``dt_ms`` ending at ``now_ms``: the sounds and speech over by then end."""
        changed = False
        for key in [k for k, s in self.sounds.items() if not s.advance(dt_ms)]:
            del self.sounds[key]
            changed = True
        if self.speech is not None and not self.speech.advance(dt_ms):
            self.speech = None
            changed = True
        if changed:
            self._mark(now_ms)

    def reset(self) -> None:
        """A simulation reset: silence (WbSpeaker's sources are deleted with the world's)."""
        if self.sounds or self.speech is not None:
            self.sounds.clear()
            self.speech = None
            self._mark(self.clock())

    @property
    def playing(self) -> list[str]:
        """The names of the sounds playing (a side's key without its suffix), in the order they started."""
        return list(dict.fromkeys(s.name for s in self.sounds.values()))

    @property
    def speaking(self) -> bool:
        return self.speech is not None

    @property
    def active(self) -> float:
        """What its ``playing`` topic publishes at each change: the sounds playing, the speech counting one."""
        return float(len(self.sounds) + (self.speech is not None))

    def readings(self) -> dict:
        return {"active": self.active}

    def step_reading(self) -> dict:
        return {"sounds": self.playing, "speaking": self.speaking}

    def describe(self) -> dict:
        return {"sounds": self.playing, "speaking": self.speaking}
