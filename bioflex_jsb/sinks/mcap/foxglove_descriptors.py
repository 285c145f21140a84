"""Foxglove's published protobuf schemas, embedded: the serialised ``FileDescriptorProto``
of each file that ``foxglove.FrameTransform``, ``foxglove.LocationFix`` and ``foxglove.Log``
need, byte for byte as the ``foxglove-schemas-protobuf`` package (0.4.0) ships them
(``<module>_pb2.DESCRIPTOR.serialized_pb``; ``tests/test_log_faults.py`` compares
:data:`FILES`, ``tests/test_events.py`` :data:`LOG_FILE`, where that package is installed).
Base64, dependencies first."""

from __future__ import annotations

import base64

_FILES = {
    "foxglove/Quaternion.proto": (
        "Chlmb3hnbG92ZS9RdWF0ZXJuaW9uLnByb3RvEghmb3hnbG92ZSI4CgpRdWF0ZXJuaW9uEgkKAXgY"
        "ASABKAESCQoBeRgCIAEoARIJCgF6GAMgASgBEgkKAXcYBCABKAFiBnByb3RvMw=="
    ),
    "foxglove/Vector3.proto": (
        "ChZmb3hnbG92ZS9WZWN0b3IzLnByb3RvEghmb3hnbG92ZSIqCgdWZWN0b3IzEgkKAXgYASABKAES"
        "CQoBeRgCIAEoARIJCgF6GAMgASgBYgZwcm90bzM="
    ),
    "google/protobuf/timestamp.proto": (
        "Ch9nb29nbGUvcHJvdG9idWYvdGltZXN0YW1wLnByb3RvEg9nb29nbGUucHJvdG9idWYiOwoJVGlt"
        "ZXN0YW1wEhgKB3NlY29uZHMYASABKANSB3NlY29uZHMSFAoFbmFub3MYAiABKAVSBW5hbm9zQoUB"
        "ChNjb20uZ29vZ2xlLnByb3RvYnVmQg5UaW1lc3RhbXBQcm90b1ABWjJnb29nbGUuZ29sYW5nLm9y"
        "Zy9wcm90b2J1Zi90eXBlcy9rbm93bi90aW1lc3RhbXBwYvgBAaICA0dQQqoCHkdvb2dsZS5Qcm90"
        "b2J1Zi5XZWxsS25vd25UeXBlc2IGcHJvdG8z"
    ),
    "foxglove/FrameTransform.proto": (
        "Ch1mb3hnbG92ZS9GcmFtZVRyYW5zZm9ybS5wcm90bxIIZm94Z2xvdmUaGWZveGdsb3ZlL1F1YXRl"
        "cm5pb24ucHJvdG8aFmZveGdsb3ZlL1ZlY3RvcjMucHJvdG8aH2dvb2dsZS9wcm90b2J1Zi90aW1l"
        "c3RhbXAucHJvdG8iwAEKDkZyYW1lVHJhbnNmb3JtEi0KCXRpbWVzdGFtcBgBIAEoCzIaLmdvb2ds"
        "ZS5wcm90b2J1Zi5UaW1lc3RhbXASFwoPcGFyZW50X2ZyYW1lX2lkGAIgASgJEhYKDmNoaWxkX2Zy"
        "YW1lX2lkGAMgASgJEiYKC3RyYW5zbGF0aW9uGAQgASgLMhEuZm94Z2xvdmUuVmVjdG9yMxImCghy"
        "b3RhdGlvbhgFIAEoCzIULmZveGdsb3ZlLlF1YXRlcm5pb25iBnByb3RvMw=="
    ),
    "foxglove/Color.proto": (
        "ChRmb3hnbG92ZS9Db2xvci5wcm90bxIIZm94Z2xvdmUiMwoFQ29sb3ISCQoBchgBIAEoARIJCgFn"
        "GAIgASgBEgkKAWIYAyABKAESCQoBYRgEIAEoAWIGcHJvdG8z"
    ),
    "foxglove/KeyValuePair.proto": (
        "Chtmb3hnbG92ZS9LZXlWYWx1ZVBhaXIucHJvdG8SCGZveGdsb3ZlIioKDEtleVZhbHVlUGFpchIL"
        "CgNrZXkYASABKAkSDQoFdmFsdWUYAiABKAliBnByb3RvMw=="
    ),
    "foxglove/LocationFix.proto": (
        "Chpmb3hnbG92ZS9Mb2NhdGlvbkZpeC5wcm90bxIIZm94Z2xvdmUaFGZveGdsb3ZlL0NvbG9yLnBy"
        "b3RvGhtmb3hnbG92ZS9LZXlWYWx1ZVBhaXIucHJvdG8aFmZveGdsb3ZlL1ZlY3RvcjMucHJvdG8a"
        "H2dvb2dsZS9wcm90b2J1Zi90aW1lc3RhbXAucHJvdG8i/AMKC0xvY2F0aW9uRml4Ei0KCXRpbWVz"
        "dGFtcBgGIAEoCzIaLmdvb2dsZS5wcm90b2J1Zi5UaW1lc3RhbXASEAoIZnJhbWVfaWQYByABKAkS"
        "EAoIbGF0aXR1ZGUYASABKAESEQoJbG9uZ2l0dWRlGAIgASgBEhAKCGFsdGl0dWRlGAMgASgBEhsK"
        "E3Bvc2l0aW9uX2NvdmFyaWFuY2UYBCADKAESTgoYcG9zaXRpb25fY292YXJpYW5jZV90eXBlGAUg"
        "ASgOMiwuZm94Z2xvdmUuTG9jYXRpb25GaXguUG9zaXRpb25Db3ZhcmlhbmNlVHlwZRIUCgdoZWFk"
        "aW5nGAogASgBSACIAQESKAoIdmVsb2NpdHkYCyABKAsyES5mb3hnbG92ZS5WZWN0b3IzSAGIAQES"
        "IwoFY29sb3IYCCABKAsyDy5mb3hnbG92ZS5Db2xvckgCiAEBEigKCG1ldGFkYXRhGAkgAygLMhYu"
        "Zm94Z2xvdmUuS2V5VmFsdWVQYWlyIlYKFlBvc2l0aW9uQ292YXJpYW5jZVR5cGUSCwoHVU5LTk9X"
        "ThAAEhAKDEFQUFJPWElNQVRFRBABEhIKDkRJQUdPTkFMX0tOT1dOEAISCQoFS05PV04QA0IKCghf"
        "aGVhZGluZ0ILCglfdmVsb2NpdHlCCAoGX2NvbG9yYgZwcm90bzM="
    ),
}
FILES: dict[str, bytes] = {name: base64.b64decode(text) for name, text in _FILES.items()}
# the files each schema needs, dependencies first
FRAME_TRANSFORM_FILES = ("foxglove/Quaternion.proto", "foxglove/Vector3.proto",
                         "google/protobuf/timestamp.proto", "foxglove/FrameTransform.proto")
LOCATION_FIX_FILES = ("foxglove/Vector3.proto", "google/protobuf/timestamp.proto",
                      "foxglove/Color.proto", "foxglove/KeyValuePair.proto",
                      "foxglove/LocationFix.proto")
# foxglove.Log (the events topic), apart from FILES (the files of the run topics); its one
# import, google/protobuf/timestamp.proto, is in FILES
LOG_FILE: bytes = base64.b64decode(
    "ChJmb3hnbG92ZS9Mb2cucHJvdG8SCGZveGdsb3ZlGh9nb29nbGUvcHJvdG9idWYvdGltZXN0YW1w"
    "LnByb3RvIuEBCgNMb2cSLQoJdGltZXN0YW1wGAEgASgLMhouZ29vZ2xlLnByb3RvYnVmLlRpbWVz"
    "dGFtcBIiCgVsZXZlbBgCIAEoDjITLmZveGdsb3ZlLkxvZy5MZXZlbBIPCgdtZXNzYWdlGAMgASgJ"
    "EgwKBG5hbWUYBCABKAkSDAoEZmlsZRgFIAEoCRIMCgRsaW5lGAYgASgHIkwKBUxldmVsEgsKB1VO"
    "S05PV04QABIJCgVERUJVRxABEggKBElORk8QAhILCgdXQVJOSU5HEAMSCQoFRVJST1IQBBIJCgVG"
    "QVRBTBAFYgZwcm90bzM="
)
LOG_FILES = ("google/protobuf/timestamp.proto", "foxglove/Log.proto")


def files(names) -> list[bytes]:
    """The serialised files ``names`` (of FILES and foxglove/Log.proto), in that order."""
    return [LOG_FILE if n == "foxglove/Log.proto" else FILES[n] for n in names]
