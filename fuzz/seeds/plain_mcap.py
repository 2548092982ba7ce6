"""Re-encodes a tdex MCAP file with uncompressed chunks and no CRCs (a fuzzing seed whose
message bytes the fuzzer can mutate without breaking a checksum or a zstd frame)."""
import sys
from mcap.reader import make_reader
from mcap.records import Metadata
from mcap.writer import Writer, CompressionType
from mcap.stream_reader import StreamReader

src, dst = sys.argv[1], sys.argv[2]
records = list(StreamReader(open(src, "rb"), skip_magic=False).records)
with open(dst, "wb") as f:
    w = Writer(f, chunk_size=4096, compression=CompressionType.NONE, enable_crcs=False)
    header = next(r for r in records if type(r).__name__ == "Header")
    w.start(profile=header.profile, library=header.library)
    schemas, channels = {}, {}
    for r in records:
        n = type(r).__name__
        if n == "Metadata":
            w.add_metadata(r.name, r.metadata)
        elif n == "Schema" and r.id not in schemas:
            schemas[r.id] = w.register_schema(r.name, r.encoding, r.data)
        elif n == "Channel" and r.id not in channels:
            channels[r.id] = w.register_channel(r.topic, r.message_encoding, schemas[r.schema_id], r.metadata)
        elif n == "Message":
            w.add_message(channels[r.channel_id], r.log_time, r.data, r.publish_time, r.sequence)
    w.finish()
