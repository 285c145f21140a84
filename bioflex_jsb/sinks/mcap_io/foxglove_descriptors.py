"""Foxglove's published protobuf schemas, embedded: the serialised ``FileDescriptorProto``
of each file that ``foxglove.FrameTransform``, ``foxglove.LocationFix``, ``foxglove.Log``
and ``foxglove.SceneUpdate`` need, byte for byte as the ``foxglove-schemas-protobuf``
package (0.4.0) ships them (``<module>_pb2.DESCRIPTOR.serialized_pb``;
``tests/test_log_faults.py`` compares :data:`FILES`, ``tests/test_events.py``
:data:`LOG_FILE`, ``tests/test_scene.py`` :data:`SCENE_FILES`, where that package is
installed). Base64, dependencies first."""

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


# foxglove.SceneUpdate (the scene topics, docs/logging.md) needs these files beyond FILES, which
# are kept apart like LOG_FILE (FILES is the run topics' set); dependencies first
_SCENE_FILES = {
    "foxglove/Pose.proto": (
        "ChNmb3hnbG92ZS9Qb3NlLnByb3RvEghmb3hnbG92ZRoZZm94Z2xvdmUvUXVhdGVybmlvbi5wcm90"
        "bxoWZm94Z2xvdmUvVmVjdG9yMy5wcm90byJWCgRQb3NlEiMKCHBvc2l0aW9uGAEgASgLMhEuZm94"
        "Z2xvdmUuVmVjdG9yMxIpCgtvcmllbnRhdGlvbhgCIAEoCzIULmZveGdsb3ZlLlF1YXRlcm5pb25i"
        "BnByb3RvMw=="
    ),
    "foxglove/ArrowPrimitive.proto": (
        "Ch1mb3hnbG92ZS9BcnJvd1ByaW1pdGl2ZS5wcm90bxIIZm94Z2xvdmUaFGZveGdsb3ZlL0NvbG9y"
        "LnByb3RvGhNmb3hnbG92ZS9Qb3NlLnByb3RvIqgBCg5BcnJvd1ByaW1pdGl2ZRIcCgRwb3NlGAEg"
        "ASgLMg4uZm94Z2xvdmUuUG9zZRIUCgxzaGFmdF9sZW5ndGgYAiABKAESFgoOc2hhZnRfZGlhbWV0"
        "ZXIYAyABKAESEwoLaGVhZF9sZW5ndGgYBCABKAESFQoNaGVhZF9kaWFtZXRlchgFIAEoARIeCgVj"
        "b2xvchgGIAEoCzIPLmZveGdsb3ZlLkNvbG9yYgZwcm90bzM="
    ),
    "foxglove/CubePrimitive.proto": (
        "Chxmb3hnbG92ZS9DdWJlUHJpbWl0aXZlLnByb3RvEghmb3hnbG92ZRoUZm94Z2xvdmUvQ29sb3Iu"
        "cHJvdG8aE2ZveGdsb3ZlL1Bvc2UucHJvdG8aFmZveGdsb3ZlL1ZlY3RvcjMucHJvdG8ibgoNQ3Vi"
        "ZVByaW1pdGl2ZRIcCgRwb3NlGAEgASgLMg4uZm94Z2xvdmUuUG9zZRIfCgRzaXplGAIgASgLMhEu"
        "Zm94Z2xvdmUuVmVjdG9yMxIeCgVjb2xvchgDIAEoCzIPLmZveGdsb3ZlLkNvbG9yYgZwcm90bzM="
    ),
    "foxglove/CylinderPrimitive.proto": (
        "CiBmb3hnbG92ZS9DeWxpbmRlclByaW1pdGl2ZS5wcm90bxIIZm94Z2xvdmUaFGZveGdsb3ZlL0Nv"
        "bG9yLnByb3RvGhNmb3hnbG92ZS9Qb3NlLnByb3RvGhZmb3hnbG92ZS9WZWN0b3IzLnByb3RvIpsB"
        "ChFDeWxpbmRlclByaW1pdGl2ZRIcCgRwb3NlGAEgASgLMg4uZm94Z2xvdmUuUG9zZRIfCgRzaXpl"
        "GAIgASgLMhEuZm94Z2xvdmUuVmVjdG9yMxIUCgxib3R0b21fc2NhbGUYAyABKAESEQoJdG9wX3Nj"
        "YWxlGAQgASgBEh4KBWNvbG9yGAUgASgLMg8uZm94Z2xvdmUuQ29sb3JiBnByb3RvMw=="
    ),
    "foxglove/Point3.proto": (
        "ChVmb3hnbG92ZS9Qb2ludDMucHJvdG8SCGZveGdsb3ZlIikKBlBvaW50MxIJCgF4GAEgASgBEgkK"
        "AXkYAiABKAESCQoBehgDIAEoAWIGcHJvdG8z"
    ),
    "foxglove/LinePrimitive.proto": (
        "Chxmb3hnbG92ZS9MaW5lUHJpbWl0aXZlLnByb3RvEghmb3hnbG92ZRoUZm94Z2xvdmUvQ29sb3Iu"
        "cHJvdG8aFWZveGdsb3ZlL1BvaW50My5wcm90bxoTZm94Z2xvdmUvUG9zZS5wcm90byKvAgoNTGlu"
        "ZVByaW1pdGl2ZRIqCgR0eXBlGAEgASgOMhwuZm94Z2xvdmUuTGluZVByaW1pdGl2ZS5UeXBlEhwK"
        "BHBvc2UYAiABKAsyDi5mb3hnbG92ZS5Qb3NlEhEKCXRoaWNrbmVzcxgDIAEoARIXCg9zY2FsZV9p"
        "bnZhcmlhbnQYBCABKAgSIAoGcG9pbnRzGAUgAygLMhAuZm94Z2xvdmUuUG9pbnQzEh4KBWNvbG9y"
        "GAYgASgLMg8uZm94Z2xvdmUuQ29sb3ISHwoGY29sb3JzGAcgAygLMg8uZm94Z2xvdmUuQ29sb3IS"
        "DwoHaW5kaWNlcxgIIAMoByI0CgRUeXBlEg4KCkxJTkVfU1RSSVAQABINCglMSU5FX0xPT1AQARIN"
        "CglMSU5FX0xJU1QQAmIGcHJvdG8z"
    ),
    "foxglove/ModelPrimitive.proto": (
        "Ch1mb3hnbG92ZS9Nb2RlbFByaW1pdGl2ZS5wcm90bxIIZm94Z2xvdmUaFGZveGdsb3ZlL0NvbG9y"
        "LnByb3RvGhNmb3hnbG92ZS9Qb3NlLnByb3RvGhZmb3hnbG92ZS9WZWN0b3IzLnByb3RvIrcBCg5N"
        "b2RlbFByaW1pdGl2ZRIcCgRwb3NlGAEgASgLMg4uZm94Z2xvdmUuUG9zZRIgCgVzY2FsZRgCIAEo"
        "CzIRLmZveGdsb3ZlLlZlY3RvcjMSHgoFY29sb3IYAyABKAsyDy5mb3hnbG92ZS5Db2xvchIWCg5v"
        "dmVycmlkZV9jb2xvchgEIAEoCBILCgN1cmwYBSABKAkSEgoKbWVkaWFfdHlwZRgGIAEoCRIMCgRk"
        "YXRhGAcgASgMYgZwcm90bzM="
    ),
    "foxglove/SpherePrimitive.proto": (
        "Ch5mb3hnbG92ZS9TcGhlcmVQcmltaXRpdmUucHJvdG8SCGZveGdsb3ZlGhRmb3hnbG92ZS9Db2xv"
        "ci5wcm90bxoTZm94Z2xvdmUvUG9zZS5wcm90bxoWZm94Z2xvdmUvVmVjdG9yMy5wcm90byJwCg9T"
        "cGhlcmVQcmltaXRpdmUSHAoEcG9zZRgBIAEoCzIOLmZveGdsb3ZlLlBvc2USHwoEc2l6ZRgCIAEo"
        "CzIRLmZveGdsb3ZlLlZlY3RvcjMSHgoFY29sb3IYAyABKAsyDy5mb3hnbG92ZS5Db2xvcmIGcHJv"
        "dG8z"
    ),
    "foxglove/TextPrimitive.proto": (
        "Chxmb3hnbG92ZS9UZXh0UHJpbWl0aXZlLnByb3RvEghmb3hnbG92ZRoUZm94Z2xvdmUvQ29sb3Iu"
        "cHJvdG8aE2ZveGdsb3ZlL1Bvc2UucHJvdG8imgEKDVRleHRQcmltaXRpdmUSHAoEcG9zZRgBIAEo"
        "CzIOLmZveGdsb3ZlLlBvc2USEQoJYmlsbGJvYXJkGAIgASgIEhEKCWZvbnRfc2l6ZRgDIAEoARIX"
        "Cg9zY2FsZV9pbnZhcmlhbnQYBCABKAgSHgoFY29sb3IYBSABKAsyDy5mb3hnbG92ZS5Db2xvchIM"
        "CgR0ZXh0GAYgASgJYgZwcm90bzM="
    ),
    "foxglove/TriangleListPrimitive.proto": (
        "CiRmb3hnbG92ZS9UcmlhbmdsZUxpc3RQcmltaXRpdmUucHJvdG8SCGZveGdsb3ZlGhRmb3hnbG92"
        "ZS9Db2xvci5wcm90bxoVZm94Z2xvdmUvUG9pbnQzLnByb3RvGhNmb3hnbG92ZS9Qb3NlLnByb3Rv"
        "IqkBChVUcmlhbmdsZUxpc3RQcmltaXRpdmUSHAoEcG9zZRgBIAEoCzIOLmZveGdsb3ZlLlBvc2US"
        "IAoGcG9pbnRzGAIgAygLMhAuZm94Z2xvdmUuUG9pbnQzEh4KBWNvbG9yGAMgASgLMg8uZm94Z2xv"
        "dmUuQ29sb3ISHwoGY29sb3JzGAQgAygLMg8uZm94Z2xvdmUuQ29sb3ISDwoHaW5kaWNlcxgFIAMo"
        "B2IGcHJvdG8z"
    ),
    "google/protobuf/duration.proto": (
        "Ch5nb29nbGUvcHJvdG9idWYvZHVyYXRpb24ucHJvdG8SD2dvb2dsZS5wcm90b2J1ZiI6CghEdXJh"
        "dGlvbhIYCgdzZWNvbmRzGAEgASgDUgdzZWNvbmRzEhQKBW5hbm9zGAIgASgFUgVuYW5vc0KDAQoT"
        "Y29tLmdvb2dsZS5wcm90b2J1ZkINRHVyYXRpb25Qcm90b1ABWjFnb29nbGUuZ29sYW5nLm9yZy9w"
        "cm90b2J1Zi90eXBlcy9rbm93bi9kdXJhdGlvbnBi+AEBogIDR1BCqgIeR29vZ2xlLlByb3RvYnVm"
        "LldlbGxLbm93blR5cGVzYgZwcm90bzM="
    ),
    "foxglove/SceneEntity.proto": (
        "Chpmb3hnbG92ZS9TY2VuZUVudGl0eS5wcm90bxIIZm94Z2xvdmUaHWZveGdsb3ZlL0Fycm93UHJp"
        "bWl0aXZlLnByb3RvGhxmb3hnbG92ZS9DdWJlUHJpbWl0aXZlLnByb3RvGiBmb3hnbG92ZS9DeWxp"
        "bmRlclByaW1pdGl2ZS5wcm90bxobZm94Z2xvdmUvS2V5VmFsdWVQYWlyLnByb3RvGhxmb3hnbG92"
        "ZS9MaW5lUHJpbWl0aXZlLnByb3RvGh1mb3hnbG92ZS9Nb2RlbFByaW1pdGl2ZS5wcm90bxoeZm94"
        "Z2xvdmUvU3BoZXJlUHJpbWl0aXZlLnByb3RvGhxmb3hnbG92ZS9UZXh0UHJpbWl0aXZlLnByb3Rv"
        "GiRmb3hnbG92ZS9UcmlhbmdsZUxpc3RQcmltaXRpdmUucHJvdG8aHmdvb2dsZS9wcm90b2J1Zi9k"
        "dXJhdGlvbi5wcm90bxofZ29vZ2xlL3Byb3RvYnVmL3RpbWVzdGFtcC5wcm90byKjBAoLU2NlbmVF"
        "bnRpdHkSLQoJdGltZXN0YW1wGAEgASgLMhouZ29vZ2xlLnByb3RvYnVmLlRpbWVzdGFtcBIQCghm"
        "cmFtZV9pZBgCIAEoCRIKCgJpZBgDIAEoCRIrCghsaWZldGltZRgEIAEoCzIZLmdvb2dsZS5wcm90"
        "b2J1Zi5EdXJhdGlvbhIUCgxmcmFtZV9sb2NrZWQYBSABKAgSKAoIbWV0YWRhdGEYBiADKAsyFi5m"
        "b3hnbG92ZS5LZXlWYWx1ZVBhaXISKAoGYXJyb3dzGAcgAygLMhguZm94Z2xvdmUuQXJyb3dQcmlt"
        "aXRpdmUSJgoFY3ViZXMYCCADKAsyFy5mb3hnbG92ZS5DdWJlUHJpbWl0aXZlEioKB3NwaGVyZXMY"
        "CSADKAsyGS5mb3hnbG92ZS5TcGhlcmVQcmltaXRpdmUSLgoJY3lsaW5kZXJzGAogAygLMhsuZm94"
        "Z2xvdmUuQ3lsaW5kZXJQcmltaXRpdmUSJgoFbGluZXMYCyADKAsyFy5mb3hnbG92ZS5MaW5lUHJp"
        "bWl0aXZlEjIKCXRyaWFuZ2xlcxgMIAMoCzIfLmZveGdsb3ZlLlRyaWFuZ2xlTGlzdFByaW1pdGl2"
        "ZRImCgV0ZXh0cxgNIAMoCzIXLmZveGdsb3ZlLlRleHRQcmltaXRpdmUSKAoGbW9kZWxzGA4gAygL"
        "MhguZm94Z2xvdmUuTW9kZWxQcmltaXRpdmViBnByb3RvMw=="
    ),
    "foxglove/SceneEntityDeletion.proto": (
        "CiJmb3hnbG92ZS9TY2VuZUVudGl0eURlbGV0aW9uLnByb3RvEghmb3hnbG92ZRofZ29vZ2xlL3By"
        "b3RvYnVmL3RpbWVzdGFtcC5wcm90byKkAQoTU2NlbmVFbnRpdHlEZWxldGlvbhItCgl0aW1lc3Rh"
        "bXAYASABKAsyGi5nb29nbGUucHJvdG9idWYuVGltZXN0YW1wEjAKBHR5cGUYAiABKA4yIi5mb3hn"
        "bG92ZS5TY2VuZUVudGl0eURlbGV0aW9uLlR5cGUSCgoCaWQYAyABKAkiIAoEVHlwZRIPCgtNQVRD"
        "SElOR19JRBAAEgcKA0FMTBABYgZwcm90bzM="
    ),
    "foxglove/SceneUpdate.proto": (
        "Chpmb3hnbG92ZS9TY2VuZVVwZGF0ZS5wcm90bxIIZm94Z2xvdmUaGmZveGdsb3ZlL1NjZW5lRW50"
        "aXR5LnByb3RvGiJmb3hnbG92ZS9TY2VuZUVudGl0eURlbGV0aW9uLnByb3RvImgKC1NjZW5lVXBk"
        "YXRlEjAKCWRlbGV0aW9ucxgBIAMoCzIdLmZveGdsb3ZlLlNjZW5lRW50aXR5RGVsZXRpb24SJwoI"
        "ZW50aXRpZXMYAiADKAsyFS5mb3hnbG92ZS5TY2VuZUVudGl0eWIGcHJvdG8z"
    ),
}
SCENE_FILES: dict[str, bytes] = {n: base64.b64decode(t) for n, t in _SCENE_FILES.items()}
SCENE_UPDATE_FILES = ("foxglove/Color.proto", "foxglove/Quaternion.proto", "foxglove/Vector3.proto",
    "foxglove/Pose.proto", "foxglove/ArrowPrimitive.proto", "foxglove/CubePrimitive.proto",
    "foxglove/CylinderPrimitive.proto", "foxglove/KeyValuePair.proto", "foxglove/Point3.proto",
    "foxglove/LinePrimitive.proto", "foxglove/ModelPrimitive.proto",
    "foxglove/SpherePrimitive.proto", "foxglove/TextPrimitive.proto",
    "foxglove/TriangleListPrimitive.proto", "google/protobuf/duration.proto",
    "google/protobuf/timestamp.proto", "foxglove/SceneEntity.proto",
    "foxglove/SceneEntityDeletion.proto", "foxglove/SceneUpdate.proto")


def files(names) -> list[bytes]:
    """The serialised files ``names`` (of FILES, SCENE_FILES and foxglove/Log.proto), in
    that order."""
    return [LOG_FILE if n == "foxglove/Log.proto" else SCENE_FILES.get(n) or FILES[n]
            for n in names]
