"""Protocol Buffers without the ``protobuf`` package: the wire format the logs are written in,
their schemas (``FileDescriptorSet`` records), and a decoder driven by a file's own schemas.

The logs' messages are protobuf (``message_encoding: protobuf``, schema encoding
``protobuf``: a serialised ``google.protobuf.FileDescriptorSet`` holding the message's file
and every file it imports), which Foxglove decodes natively. ``foxglove.FrameTransform``,
``foxglove.LocationFix`` and ``foxglove.Log`` are Foxglove's published schemas, embedded
byte for byte (:mod:`.foxglove_descriptors`); the ``bioflex.*`` schemas are built here from
their field lists. Messages are written by :mod:`.formatting` with numpy, a chunk at a
time; this module only knows the wire format: varints, tags, length-delimited fields
(``protobuf.dev``, "Encoding").
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Sequence

# wire types
VARINT, I64, LEN, I32 = 0, 1, 2, 5
# FieldDescriptorProto.Type values used here and in the decoder
TYPE_DOUBLE, TYPE_FLOAT, TYPE_INT64, TYPE_UINT64, TYPE_INT32 = 1, 2, 3, 4, 5
TYPE_FIXED64, TYPE_FIXED32, TYPE_BOOL, TYPE_STRING, TYPE_MESSAGE = 6, 7, 8, 9, 11
TYPE_BYTES, TYPE_UINT32, TYPE_ENUM, TYPE_SFIXED32, TYPE_SFIXED64 = 12, 13, 14, 15, 16
TYPE_SINT32, TYPE_SINT64 = 17, 18
LABEL_OPTIONAL, LABEL_REPEATED = 1, 3
TIMESTAMP = "google.protobuf.Timestamp"


def varint(n: int) -> bytes:
    """``n`` ≥ 0 as a canonical (shortest) base-128 varint."""
    if n < 0:
        n &= (1 << 64) - 1  # negative int64/int32: ten bytes, two's complement
    out = bytearray()
    while n > 0x7F:
        out.append((n & 0x7F) | 0x80)
        n >>= 7
    out.append(n)
    return bytes(out)


def varint_length(n: int) -> int:
    return len(varint(n))


def tag(number: int, wire_type: int) -> bytes:
    return varint((number << 3) | wire_type)


def length_delimited(number: int, payload: bytes) -> bytes:
    return tag(number, LEN) + varint(len(payload)) + payload


def string_field(number: int, text: str) -> bytes:
    return length_delimited(number, text.encode())


def int_field(number: int, n: int) -> bytes:
    return tag(number, VARINT) + varint(n)


# -- schemas of our own messages: FileDescriptorProto records -------------------------------
def _field_descriptor(name: str, number: int, type_: int, repeated: bool = False,
                      type_name: str | None = None) -> bytes:
    out = (string_field(1, name) + int_field(3, number)
           + int_field(4, LABEL_REPEATED if repeated else LABEL_OPTIONAL) + int_field(5, type_))
    if type_name:
        out += string_field(6, "." + type_name)
    return out + string_field(10, name)  # json_name: the field name as it is


def file_descriptor(package: str, message: str, fields: Sequence[tuple[str, int, bool]]
                    ) -> bytes:
    """A proto3 ``FileDescriptorProto`` (``<package>/<message>.proto``) of one message whose
    ``fields`` are (name, field number, repeated) doubles."""
    body = string_field(1, message)
    for name, number, repeated in fields:
        body += length_delimited(2, _field_descriptor(name, number, TYPE_DOUBLE, repeated))
    return (string_field(1, f"{package}/{message}.proto") + string_field(2, package)
            + length_delimited(4, body) + string_field(12, "proto3"))


def _enum_descriptor(name: str, values: Sequence[str]) -> bytes:
    """An ``EnumDescriptorProto``: ``values`` numbered from 0 (proto3: the first is 0)."""
    body = string_field(1, name)
    for number, value in enumerate(values):
        body += length_delimited(2, string_field(1, value) + int_field(2, number))
    return body


def typed_file_descriptor(package: str, message: str,
                          fields: Sequence[tuple[str, int, bool, int, str | None]],
                          enums: Sequence[tuple[str, Sequence[str]]] = ()) -> bytes:
    """A proto3 ``FileDescriptorProto`` of one message whose ``fields`` are (name, number,
    repeated, FieldDescriptorProto type, enum name or None) and whose nested ``enums`` are
    (name, value names); an enum field's type name is ``<package>.<message>.<enum>``."""
    body = string_field(1, message)
    for name, number, repeated, type_, enum in fields:
        type_name = f"{package}.{message}.{enum}" if enum else None
        body += length_delimited(2, _field_descriptor(name, number, type_, repeated, type_name))
    for name, values in enums:
        body += length_delimited(4, _enum_descriptor(name, values))
    return (string_field(1, f"{package}/{message}.proto") + string_field(2, package)
            + length_delimited(4, body) + string_field(12, "proto3"))


def file_descriptor_set(files: Sequence[bytes]) -> bytes:
    """A ``FileDescriptorSet`` of serialised ``FileDescriptorProto`` records (dependencies
    first)."""
    return b"".join(length_delimited(1, f) for f in files)


# -- reading: a wire-format parser and a decoder built from a FileDescriptorSet -------------
def read_varint(data, pos: int) -> tuple[int, int]:
    """(value, next position) of the varint at ``pos``; ValueError if it does not end."""
    result = shift = 0
    while True:
        if pos >= len(data) or shift > 63:
            raise ValueError("truncated or overlong varint")
        b = data[pos]
        pos += 1
        result |= (b & 0x7F) << shift
        if b < 0x80:
            return result, pos
        shift += 7


def iter_fields(data):
    """(field number, wire type, value) of every field of a serialised message: an int for
    VARINT, the raw 8 or 4 bytes for I64/I32, a memoryview for LEN."""
    data = memoryview(data)
    pos, n = 0, len(data)
    while pos < n:
        key, pos = read_varint(data, pos)
        number, wire = key >> 3, key & 7
        if wire == VARINT:
            value, pos = read_varint(data, pos)
        elif wire == I64:
            value, pos = data[pos:pos + 8], pos + 8
        elif wire == I32:
            value, pos = data[pos:pos + 4], pos + 4
        elif wire == LEN:
            size, pos = read_varint(data, pos)
            value, pos = data[pos:pos + size], pos + size
        else:
            raise ValueError(f"unsupported protobuf wire type {wire}")
        if pos > n:
            raise ValueError("truncated protobuf field")
        yield number, wire, value


def _messages_of(fdset: bytes) -> dict[str, dict[int, tuple[str, int, int, str]]]:
    """Every message type of a FileDescriptorSet: full name → {number: (name, type, label,
    type name)} (nested types included)."""
    out: dict[str, dict[int, tuple[str, int, int, str]]] = {}

    def message(prefix: str, data) -> None:
        name, fields, nested = "", {}, []
        for num, _, val in iter_fields(data):
            if num == 1:
                name = bytes(val).decode()
            elif num == 2:
                f = {"name": "", "number": 0, "label": LABEL_OPTIONAL, "type": 0,
                     "type_name": ""}
                for fnum, _, fval in iter_fields(val):
                    if fnum == 1:
                        f["name"] = bytes(fval).decode()
                    elif fnum == 3:
                        f["number"] = fval
                    elif fnum == 4:
                        f["label"] = fval
                    elif fnum == 5:
                        f["type"] = fval
                    elif fnum == 6:
                        f["type_name"] = bytes(fval).decode().lstrip(".")
                fields[f["number"]] = (f["name"], f["type"], f["label"], f["type_name"])
            elif num == 3:
                nested.append(val)
        full = f"{prefix}.{name}" if prefix else name
        out[full] = fields
        for n in nested:
            message(full, n)

    for num, _, fdp in iter_fields(fdset):
        if num != 1:
            continue
        package = ""
        types = []
        for fnum, _, val in iter_fields(fdp):
            if fnum == 2:
                package = bytes(val).decode()
            elif fnum == 4:
                types.append(val)
        for t in types:
            message(package, t)
    return out


_FIXED = {TYPE_DOUBLE: "<d", TYPE_FIXED64: "<Q", TYPE_SFIXED64: "<q", TYPE_FLOAT: "<f",
          TYPE_FIXED32: "<I", TYPE_SFIXED32: "<i"}


def _scalar(type_: int, wire: int, value):
    if wire == VARINT:
        if type_ in (TYPE_INT64, TYPE_INT32, TYPE_ENUM) and value >= 1 << 63:
            return value - (1 << 64)
        if type_ in (TYPE_SINT32, TYPE_SINT64):
            return (value >> 1) ^ -(value & 1)
        if type_ == TYPE_BOOL:
            return bool(value)
        return value
    if wire in (I64, I32):
        return struct.unpack(_FIXED.get(type_, "<d" if wire == I64 else "<f"), value)[0]
    if type_ == TYPE_STRING:
        return bytes(value).decode()
    return bytes(value)


def decoder(fdset: bytes, full_name: str) -> Callable[[bytes], dict]:
    """A function that decodes a serialised ``full_name`` message into a dict of the fields
    present on the wire (names as in the schema; repeated fields as lists; a
    ``google.protobuf.Timestamp`` as ``{"sec", "nsec"}``, the names of Foxglove's JSON
    schemas, so a protobuf log reads back like an old JSON one). ValueError for data that
    does not parse or a schema without the type."""
    types = _messages_of(fdset)
    if full_name not in types:
        raise ValueError(f"the schema does not define {full_name}")

    def decode(data, name: str = full_name) -> dict:
        fields = types.get(name, {})
        out: dict = {}
        for number, wire, value in iter_fields(data):
            spec = fields.get(number)
            if spec is None:
                continue  # unknown field: skipped, as protobuf readers do
            fname, type_, label, type_name = spec
            if type_ == TYPE_MESSAGE:
                v = decode(value, type_name)
                if type_name == TIMESTAMP:
                    v = {"sec": v.get("seconds", 0), "nsec": v.get("nanos", 0)}
            elif wire == LEN and label == LABEL_REPEATED and type_ in _FIXED:  # packed
                fmt = _FIXED[type_]
                size = struct.calcsize(fmt)
                if len(value) % size:
                    raise ValueError(f"packed field {fname} of {len(value)} bytes")
                out.setdefault(fname, []).extend(
                    struct.unpack(f"<{len(value) // size}{fmt[1]}", value))
                continue
            elif wire == LEN and label == LABEL_REPEATED and type_ not in (
                    TYPE_STRING, TYPE_BYTES):  # packed varints
                items, pos = [], 0
                while pos < len(value):
                    n, pos = read_varint(value, pos)
                    items.append(_scalar(type_, VARINT, n))
                out.setdefault(fname, []).extend(items)
                continue
            else:
                v = _scalar(type_, wire, value)
            if label == LABEL_REPEATED:
                out.setdefault(fname, []).append(v)
            else:
                out[fname] = v
        return out

    return decode
