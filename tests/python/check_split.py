#!/usr/bin/env python3
"""Open a friction-node split recording (a rosbag2 directory) with the
independent Python readers: `rosbags` opens the directory as one bag, and the
`mcap` reader opens every file alone. Checks that every message of
metadata.yaml is there once and that the estimates' stamps continue across
the splits with no gap and no repeat.

Usage: check_split.py DIR [--min-files N]
"""
import argparse
import pathlib
import sys

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--min-files", type=int, default=2)
    args = ap.parse_args()
    d = pathlib.Path(args.dir)
    files = sorted(d.glob("*.mcap"), key=lambda p: int(p.stem.rsplit("_", 1)[1]))
    assert len(files) >= args.min_files, f"{len(files)} files"

    # Every file alone, with the mcap reader.
    per_file = {}
    stamps = []
    for f in files:
        with open(f, "rb") as fh:
            reader = make_reader(fh, decoder_factories=[DecoderFactory()])
            summary = reader.get_summary()
            assert summary is not None, f"{f}: not finalised"
            # The node's seven topics and /parameter_events.
            assert len(summary.channels) == 8, f"{f}: {len(summary.channels)} channels"
            n = 0
            for schema, channel, message, decoded in reader.iter_decoded_messages():
                n += 1
                if schema.name == "friction_msgs/msg/FrictionEstimate":
                    stamps.append(message.publish_time)
            per_file[f.name] = n
    assert stamps == sorted(stamps), "estimates in order"
    assert len(set(stamps)) == len(stamps), "no estimate repeated"
    gaps = [b - a for a, b in zip(stamps, stamps[1:])]
    step = min(gaps)
    assert max(gaps) < 50 * step, f"a gap of {max(gaps)} ns between estimates"

    # The directory as one bag, with rosbags.
    store = get_typestore(Stores.ROS2_HUMBLE)
    with AnyReader([d], default_typestore=store) as reader:
        total = 0
        estimates = 0
        for conn, t, raw in reader.messages():
            total += 1
            if conn.msgtype == "friction_msgs/msg/FrictionEstimate":
                estimates += 1
    assert total == sum(per_file.values()), f"rosbags read {total}, the files hold {sum(per_file.values())}"
    assert estimates == len(stamps)
    print(f"{len(files)} files, {total} messages ({estimates} estimates) read by rosbags as one bag and by mcap file by file")
    return 0


if __name__ == "__main__":
    sys.exit(main())
