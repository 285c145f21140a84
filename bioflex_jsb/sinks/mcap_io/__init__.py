"""A domain-free MCAP and protobuf toolkit: nothing here knows of aircraft, runs or topics.

* :mod:`.writer`: an MCAP file writer, hand-written because it is measured faster than the
  ``mcap`` package's for this project's many small messages (docs/performance.md), with
  chunks closed under a critical section so that a signal never leaves half a record;
* :mod:`.records`: protobuf message records of a chunk built by one compiled pass (fixed
  layouts, the varint timestamps the only variable bytes);
* :mod:`.protobuf`: protobuf wire-format pieces and a decoder built from a file's own
  descriptor set; :mod:`.foxglove_descriptors`: Foxglove's well-known schemas;
* :mod:`.recover`: every chunk's CRC checked, and a damaged or unfinished file's intact
  chunks copied into a finished one;
* :mod:`.errors`: the one-line errors of reading and writing.

The run log (:mod:`bioflex_jsb.sinks.mcap`) builds on it.
"""
