#!/usr/bin/env python3
"""How much does each recorded period's mantle conduct? (diagnostic,
docs/validation.md#fresh-boundary-maps)

usage: wall_conductance.py RECORDING.mcap [RECORDING.mcap ...]
       (recordings of one case on different seeds, with a conducting wall)

For each recorded period of each recording, the sum over its wall rows of sqrt(contact area)
times the contact's duration in steps: proportional to the period's wall conductance
integral, since every wall row of a drum has the same conductivities. Printed as each
period's difference, in %, from the mean over every period given. A recorded period that
conducted more than the others heats a replay of it faster, whatever its map.
"""
import json
import statistics
import sys

from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory


def wall_sums(path):
    """The per-period sums of sqrt(area) x duration over the wall rows of a recording."""
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        info = {m.name: json.loads(m.metadata["json"]) for m in reader.iter_metadata()}["tdex.recording"]
        particles, period = info["particles"], info["period_steps"]
        unit = info["sqrt_area_unit"] if info["area_encoding"] == "quantized" else 1.0
        sums = [0.0] * info["recorded_periods"]
        for _, _, _, batch in reader.iter_decoded_messages(topics=["/tdex/collisions"]):
            area = batch.sqrt_area_code if info["area_encoding"] == "quantized" else batch.sqrt_area
            for j, start, duration, a in zip(batch.j, batch.start_step, batch.duration_steps, area):
                if j >= particles:  # a wall: its id follows the particles'
                    sums[start // period] += a * unit * duration
        return sums


def main(paths):
    sums = {path: wall_sums(path) for path in paths}
    every = [s for per in sums.values() for s in per]
    mean = statistics.mean(every)
    for path, per in sums.items():
        print(f"{path}: " + ", ".join(f"period {p + 1} {100 * (s / mean - 1):+.2f} %" for p, s in enumerate(per)))
    if len(every) > 1:
        print(f"{len(every)} periods: standard deviation {100 * statistics.stdev(every) / mean:.2f} % of their mean")


if __name__ == "__main__":
    main(sys.argv[1:])
