"""Webots' Speaker functions (``wb_speaker_*``) on Sensorium; :mod:`sensorium.client.wb` re-exports them.

A headless server plays no audio, but a speaker's state follows Webots (README "The Speaker"):
``play_sound`` reads the sound file here, as libController does (a path relative to the
controller's folder, where ``sensorium controller`` starts it, or absolute), and tells the server
its length (a WAV's frames and rate, read with :mod:`wave`); the sound then plays in simulated
time and the step reply that ends it says so. ``is_sound_playing``/``is_speaking`` answer this
controller's copy at once (True from the call, False once a step reply says it is over or after
``stop``), as libController's do. The engine and language are libController's own state: ``"pico"``
and ``"en-US"`` at start, the setters accepting what Webots' accept off Windows (the ``pico`` engine
and its six languages). Webots' lines for out-of-range volumes, pitches and balances; a missing or
unreadable file is WbSpeaker's one warning line and plays nothing."""

from __future__ import annotations

import math
import sys
import wave
from typing import Any

from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_robot import DeviceState, answers, c_string, current, real

SPEAKER = "Speaker"
ENGINES = ("pico",)
LANGUAGES = ("en-US", "en-UK", "de-DE", "es-ES", "fr-FR", "it-IT")
"""What ``set_engine`` and ``set_language`` accept (libController's pico languages)."""
MAX_RATE = 1 << 31
"""A WAV's frame rate must be below this (a header's is 32 bits; past this one it is a damaged file)."""
MAX_PITCH = 1e9
"""The greatest pitch the server takes (a sound faster than that lasts less than a nanosecond a
second of audio); a greater one, +inf too, is clamped to it with a warning line (Webots sends it to OpenAL)."""

__all__ = ["ENGINES", "LANGUAGES", "SPEAKER", "wb_speaker_get_engine", "wb_speaker_get_language",
           "wb_speaker_is_sound_playing", "wb_speaker_is_speaking", "wb_speaker_play_sound", "wb_speaker_set_engine",
           "wb_speaker_set_language", "wb_speaker_speak", "wb_speaker_stop", "sound_length"]


def _err(line: str) -> None:
    print(line, file=sys.stderr)


def _sounds(dev: DeviceState) -> dict[str, Any]:
    """This controller's sounds of a speaker: name -> [frames, rate, playing] (libController's list)."""
    return dev.desc.setdefault("_sounds", {})  # type: ignore[no-any-return]


def sound_length(path: str) -> tuple[int, int] | str:
    """A WAV file's (frames, frames per second), or why it cannot be played: ``"missing"`` or ``"format"``
    (WbSpeaker plays 8 or 16 bit mono or stereo waves; a rate of 0 or of 2**31 frames/s or more is a damaged header)."""
    try:
        with wave.open(path, "rb") as w:
            if w.getsampwidth() not in (1, 2) or w.getnchannels() not in (1, 2) or not 0 < w.getframerate() < MAX_RATE:
                return "format"
            return w.getnframes(), w.getframerate()
    except FileNotFoundError:
        return "missing"
    except ValueError:                                  # a NUL inside: no file has that name
        return "missing"
    except (OSError, EOFError, wave.Error):
        return "format"


def _clamped(func: str, name: str, value: float, lo: float | None, hi: float | None) -> float:
    """Webots' warning of wb_speaker_play_sound for a value outside its range, and the value kept."""
    if lo is not None and value < lo:
        what = f"a negative {name} value" if lo == 0.0 else f"a {name} value less than {lo:g}"
        _err(f"Warning: {func}() called with {what}: {value:g}. Setting {name} to {lo:g}.")
        return lo
    if hi is not None and value > hi:
        _err(f"Warning: {func}() called with a {name} value greater than {hi:g}: {value:g}. Setting {name} to {hi:g}.")
        return hi
    return value


def _number(func: str, name: str, v: Any) -> float:
    """``v`` as a float (NaN kept: the caller says it in Webots' way); not a number raises."""
    x = real(v)
    if x is None:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): '{name}' must be a number, got {v!r}")
    return x


def _play(dev: DeviceState, sound: str, volume: float, pitch: float, balance: float, loop: bool, side: int) -> None:
    func = "wb_speaker_play_sound"
    r = current()
    mine = _sounds(dev)
    known = mine.get(sound)
    if known is None:
        length = sound_length(sound)
        if length == "missing":
            _err(f"Warning: {func}(): Sound file '{sound}' not found. The sound file should be defined relatively to "
                 "the controller, the PROTO or absolutely.")
            return
        if isinstance(length, str):
            _err(f"Warning: {func}(): Impossible to play '{sound}'. Make sure the file format is supported (8 or 16 "
                 "bits, mono or stereo wave).")
            return
        known = mine[sound] = [length[0], length[1], False]
    if not r.terminated:
        r._expect_success(r.rpc(dev, "play_sound", {
            "sound": sound, "frames": int(known[0]), "rate": int(known[1]), "volume": volume, "pitch": pitch,
            "balance": balance, "loop": bool(loop), "side": side}), func)
    known[2] = True


def _tag(tag: Any, which: str, func: str) -> DeviceState | None:
    if not tag:
        return None
    r = current()
    try:
        return r.device(tag, SPEAKER, func)
    except SensoriumError:
        _err(f"Error: {func}(): invalid '{which}' device tag.")
        raise


@answers(None)
def wb_speaker_play_sound(left: int, right: int, sound: str, volume: float, pitch: float, balance: float,
                          loop: bool) -> None:
    """Play ``sound`` (a WAV file) on ``left`` and/or ``right`` (0: none), as libController splits it:
    one speaker given twice plays it on both channels at ``volume``; two speakers each play their
    side at the volume the balance leaves it."""
    sound = c_string(sound)
    func = "wb_speaker_play_sound"
    if not isinstance(sound, str):
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): 'sound' must be a string, got {sound!r}")
    try:
        left_dev = _tag(left, "left", func)
        right_dev = _tag(right, "right", func)
    except SensoriumError:
        return
    numbers = [_number(func, "volume", volume), _number(func, "pitch", pitch), _number(func, "balance", balance)]
    if any(math.isnan(x) for x in numbers):              # the C library's line; nothing plays
        _err(f"Error: {func}() called with an invalid argument (a NULL sound or a NaN value).")
        return
    volume = _clamped(func, "volume", numbers[0], 0.0, 1.0)
    pitch = _clamped(func, "pitch", numbers[1], 0.0, MAX_PITCH)
    balance = _clamped(func, "balance", numbers[2], -1.0, 1.0)
    if balance <= 0.0:
        left_volume, right_volume = volume, volume * (1.0 + balance)
    else:
        left_volume, right_volume = volume * (1.0 - balance), volume
    if left == right and volume > 0.0 and left_dev is not None:
        _play(left_dev, sound, volume, pitch, balance, bool(loop), 0)
        return
    if left_volume > 0.0 and left_dev is not None:
        _play(left_dev, sound, left_volume, pitch, 0.0, bool(loop), -1)
    if right_volume > 0.0 and right_dev is not None:
        _play(right_dev, sound, right_volume, pitch, 0.0, bool(loop), 1)


@answers(None)
def wb_speaker_stop(tag: int, sound: str | None) -> None:
    """Stop ``sound``, or with None or "" every sound and the speech."""
    sound = c_string(sound)
    func = "wb_speaker_stop"
    r = current()
    dev = r.device(tag, SPEAKER, func)
    if sound is not None and not isinstance(sound, str):
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): 'sound' must be a string or None, got {sound!r}")
    name = sound or ""
    if not r.terminated:
        r._expect_success(r.rpc(dev, "stop", {"value": name}), func)
    for key, known in _sounds(dev).items():
        if not name or key == name:
            known[2] = False
    if not name:
        dev.desc["_speech"] = None


@answers(False)
def wb_speaker_is_sound_playing(tag: int, sound: str | None) -> bool:
    """Whether ``sound`` plays; with None or "" whether anything plays or is spoken."""
    sound = c_string(sound)
    func = "wb_speaker_is_sound_playing"
    dev = current().device(tag, SPEAKER, func)
    if sound is not None and not isinstance(sound, str):
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): 'sound' must be a string or None, got {sound!r}")
    mine = _sounds(dev)
    if not sound:
        return dev.desc.get("_speech") is not None or any(k[2] for k in mine.values())
    known = mine.get(sound)
    return bool(known and known[2])


@answers(False)
def wb_speaker_set_engine(tag: int, engine: str) -> bool:
    engine = c_string(engine)
    dev = current().device(tag, SPEAKER, "wb_speaker_set_engine")
    if engine not in ENGINES:
        return False
    dev.desc["engine"] = engine
    return True


@answers(False)
def wb_speaker_set_language(tag: int, language: str) -> bool:
    """libController's rule: a malformed code is one error line and False, a well-formed one the
    engine does not speak is False silently, a language it speaks True."""
    language = c_string(language)
    func = "wb_speaker_set_language"
    dev = current().device(tag, SPEAKER, func)
    lang = language if isinstance(language, str) else ""
    ok = (len(lang) == 5 and lang[2] == "-" and lang[:2].isascii() and lang[:2].islower() and lang[:2].isalpha()
          and lang[3:].isascii() and lang[3:].isupper() and lang[3:].isalpha())
    if not ok:
        engine = dev.desc.get("engine", "pico")
        _err(f"Error: {func}() called with an invalid 'language' argument: \"{language}\". 'language' should follow "
             "the \"ll-CC\" format where ll is the ISO 639-1 language code and CC is the ISO 3166 country code, for "
             f"example, \"en-US\" or \"fr-FR\"; the \"{engine}\" engine speaks "
             + ", ".join(f'"{x}"' for x in LANGUAGES) + ".")
        return False
    if lang not in LANGUAGES:
        return False
    dev.desc["language"] = lang
    return True


@answers("")
def wb_speaker_get_engine(tag: int) -> str:
    return str(current().device(tag, SPEAKER, "wb_speaker_get_engine").desc.get("engine", "pico"))


@answers("")
def wb_speaker_get_language(tag: int) -> str:
    return str(current().device(tag, SPEAKER, "wb_speaker_get_language").desc.get("language", "en-US"))


@answers(None)
def wb_speaker_speak(tag: int, text: str, volume: float) -> None:
    """Speak ``text`` (it replaces what is being spoken); no synthesiser: it lasts 0.4 s a word."""
    text = c_string(text)
    func = "wb_speaker_speak"
    r = current()
    dev = r.device(tag, SPEAKER, func)
    if not isinstance(text, str):
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): 'text' must be a string, got {text!r}")
    x = _number(func, "volume", volume)
    if math.isnan(x):                                    # the C library's line; nothing is spoken
        _err(f"Error: {func}() called with an invalid argument (a NULL text or a NaN volume).")
        return
    if x < 0.0:
        _err(f"Warning: {func}() called with negative volume value: {x:g}. Setting volume to 0.")
        x = 0.0
    elif x > 1.0:
        _err(f"Warning: {func}() called with volume value greater than 1: {x:g}. Setting volume to 1.")
        x = 1.0
    if not r.terminated:
        r._expect_success(r.rpc(dev, "speak", {"text": text, "volume": x}), func)
    dev.desc["_speech"] = text


@answers(False)
def wb_speaker_is_speaking(tag: int) -> bool:
    return current().device(tag, SPEAKER, "wb_speaker_is_speaking").desc.get("_speech") is not None
