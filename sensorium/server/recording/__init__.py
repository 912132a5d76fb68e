"""Recording and playback: MCAP files written from the daemon's published messages, replay
onto topics, export to ROS 2 formats.

* :mod:`.envelope` — format constants, the topic envelope, ``--topics`` matching;
* :mod:`.writer`   — ``McapRecorder`` (the hook the daemon's topics call), ``recorder_for_server``;
* :mod:`.reader`   — ``Recording``: messages in time order, summaries, truncated files;
* :mod:`.live`     — ``record --connect``: a subscriber that records and counts gaps (zmq client);
* :mod:`.replay`   — republish a recording on a live server's socket layout (zmq, binds);
* :mod:`.export`   — ROS 2 (CDR) bags and MCAP files.

Depends on the daemon only through the recorder hook (duck-typed), never the reverse; imports
schemas; never cli.
"""
