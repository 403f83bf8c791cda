"""``zenav record`` and ``zenav replay``: a robot's messages in an MCAP file.

MCAP is the robotics log format (Foxglove, ROS 2's default bag format); the ``mcap``
tools (``mcap info``, ``mcap cat``) and libraries read these files. Layout:

- one **channel per key** (``zenav/<robot>/scan``, ...), message encoding ``msgpack``:
  each message's data is the exact payload that was on the bus (zenav's msgpack map with
  its ``_v``/``_t`` envelope), so a replay is byte for byte what the services saw;
- one **schema per message type**, encoding ``jsonschema``, named ``zenav.<Type>``: the
  pydantic model's JSON Schema (serialization mode), as ``zenav schemas`` writes it;
- **log time**: wall clock (ns) when the recorder received the message, taken in Zenoh's
  callback; **publish time**: the message's own ``stamp`` (ns on the stack's clock:
  simulated seconds in simulation); **sequence**: the message's ``seq``;
- liveliness changes as channels ``zenav/<robot>/alive/<service>``, encoding ``json``,
  data ``{"alive": true|false}``;
- metadata record ``zenav``: robot id, schema version, zenav version.

``MsgpackDecoderFactory`` lets ``mcap.reader.make_reader(f, decoder_factories=[...])``
``.iter_decoded_messages()`` return the pydantic messages.

A replay publishes the recorded payloads on the same keys (or another robot id's), in
log-time order, at the recorded pace divided by ``--rate``. Services remember the latest
stamp they saw: start them afresh before each replay.

Modules: :mod:`.mcapfile` (the file: writer, reader, decoder), :mod:`.record` and
:mod:`.replay` (the processes and their commands).
"""
