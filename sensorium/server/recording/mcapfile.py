"""Compatibility: the recording module was split by job (kept for branches in flight; import from
the new modules instead):

* :mod:`.envelope` — format constants, the topic envelope, ``--topics`` matching;
* :mod:`.writer`   — ``McapRecorder``, ``recorder_for_server``;
* :mod:`.reader`   — ``Recording``, ``RecordedMessage``, ``iter_messages``, ``summarize``;
* ``sensorium info FILE.mcap`` printing is :func:`sensorium.cli.recording.print_info`.
"""

from sensorium.server.recording.envelope import (  # noqa: F401
    DEFAULT_CHUNK_SIZE,
    MAGIC,
    MESSAGE_ENCODING,
    PROFILE,
    SEQ_MODULUS,
    pack_envelope,
    topic_matcher,
)
from sensorium.server.recording.reader import RecordedMessage, Recording, TopicInfo, iter_messages, summarize  # noqa: F401
from sensorium.server.recording.writer import McapRecorder, recorder_for_server  # noqa: F401
