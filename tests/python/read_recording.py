#!/usr/bin/env python3
"""Reads a tdex recording with the standard MCAP readers from PyPI (`mcap`,
`mcap-protobuf-support`) and checks it against `tdex inspect --json`.

usage: read_recording.py RECORDING.mcap INSPECT.json
Decodes every collision batch and every snapshot; exits non-zero on any mismatch.
"""
import json
import math
import struct
import sys

from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory


def main(recording, inspect_json):
    with open(inspect_json) as f:
        expected = json.load(f)
    rows = batches = contact_steps = 0
    snapshots = {}
    with open(recording, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        header = reader.get_header()
        assert header.profile == "tdex", header.profile
        meta = {m.name: json.loads(m.metadata["json"]) for m in reader.iter_metadata()}
        info = meta["tdex.recording"]
        for schema, channel, message, decoded in reader.iter_decoded_messages():
            if channel.topic == "/tdex/collisions":
                assert schema.name == "tdex.CollisionBatch"
                n = len(decoded.i)
                columns = [decoded.j, decoded.start_step, decoded.duration_steps]
                area = decoded.sqrt_area_code if info["area_encoding"] == "quantized" else decoded.sqrt_area
                assert all(len(c) == n for c in columns + [area]), "ragged batch"
                assert decoded.first_row == rows, (decoded.first_row, rows)
                assert all(i < j for i, j in zip(decoded.i, decoded.j))
                rows += n
                batches += 1
                contact_steps += sum(decoded.duration_steps)
            elif channel.topic == "/tdex/snapshots":
                assert schema.name == "foxglove.PointCloud"
                names = [fl.name for fl in decoded.fields]
                assert names[:4] == ["x", "y", "z", "temperature"], names
                stride = decoded.point_stride
                count = len(decoded.data) // stride
                points = [struct.unpack_from("<4dI4d", decoded.data, k * stride) for k in range(count)]
                snapshots[message.sequence] = points
    assert rows == expected["rows"], (rows, expected["rows"])
    assert batches == expected["batches"], (batches, expected["batches"])
    assert contact_steps == expected["contact_steps"], (contact_steps, expected["contact_steps"])
    assert sorted(snapshots) == [s["index"] for s in expected["snapshots"]], sorted(snapshots)
    for s in expected["snapshots"]:
        points = snapshots[s["index"]]
        assert len(points) == expected["particles"]
        assert [p[4] for p in points] == list(range(len(points))), "ids not in order"
        mean_t = sum(p[3] for p in points) / len(points)
        mean_pos = [sum(p[a] for p in points) / len(points) for a in range(3)]
        assert math.isclose(mean_t, s["mean_temperature"], rel_tol=1e-12), (mean_t, s)
        for a in range(3):
            assert math.isclose(mean_pos[a], s["mean_position"][a], rel_tol=1e-9, abs_tol=1e-15), (mean_pos, s)
    print(f"python mcap reader: {rows} rows in {batches} batches, {len(snapshots)} snapshots: all match tdex inspect")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
