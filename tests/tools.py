"""The test extra's command-line programs, found beside this interpreter (its environment's
``bin/``), never on PATH: a test must not depend on what PATH happens to hold."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest


def env_program(name: str) -> str:
    """The program ``name`` of this Python's environment (e.g. ``pymcap-cli``, ``jsbsim``);
    the test fails, saying what to install, when it is not there."""
    exe = Path(sys.executable).parent / name
    if not exe.exists():
        pytest.fail(f"{exe} is missing: install the test extra (pip install '.[test]')")
    return str(exe)


def protobuf_class(schema_name: str, descriptor_set: bytes):
    """The message class of ``schema_name`` built by Google's protobuf runtime from a
    serialised FileDescriptorSet (a log's or a live channel's own schema): an independent
    decoder of what the project's writer encodes."""
    pytest.importorskip("google.protobuf")
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

    pool = descriptor_pool.DescriptorPool()
    for fd in descriptor_pb2.FileDescriptorSet.FromString(descriptor_set).file:
        pool.Add(fd)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(schema_name))


def decode_topic(path, topic_name: str) -> list:
    """[(log time [ns], message)] of a log's topic, decoded by Google's protobuf runtime from
    the file's own schema (read with the ``mcap`` package's reader)."""
    from mcap.reader import make_reader

    out, cls = [], None
    with open(path, "rb") as f:
        for schema, _channel, message in make_reader(f).iter_messages(topics=[topic_name]):
            if cls is None:
                cls = protobuf_class(schema.name, schema.data)
            out.append((message.log_time, cls.FromString(message.data)))
    return out


def channel_metadata(path, topic_name: str) -> dict:
    """The metadata of a log's channel ``topic_name`` (empty if the topic is not there)."""
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    for channel in summary.channels.values():
        if channel.topic == topic_name:
            return dict(channel.metadata)
    return {}


def published_files(*descriptors) -> dict[str, bytes]:
    """Name → serialised FileDescriptorProto of the published ``descriptors`` (e.g. a
    foxglove_schemas_protobuf module's DESCRIPTOR) and their imports, imports first: what the
    embedded Foxglove schemas must equal byte for byte."""
    published: dict[str, bytes] = {}

    def add(fd):
        for dep in fd.dependencies:
            add(dep)
        published[fd.name] = fd.serialized_pb

    for d in descriptors:
        add(d)
    return published
