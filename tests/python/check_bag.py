#!/usr/bin/env python3
"""Decode a friction-node MCAP bag with the independent Python readers
(mcap + mcap-ros2-support) and check what must be in it.

Usage: check_bag.py BAG.mcap [--min-estimates N]
Exit status 0 when every message decodes and the bag has the expected
content; prints a per-topic summary.
"""
import argparse
import sys

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("bag")
    ap.add_argument("--min-estimates", type=int, default=1)
    args = ap.parse_args()

    with open(args.bag, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        header = reader.get_header()
        assert header.profile == "ros2", f"profile {header.profile!r}"
        summary = reader.get_summary()
        assert summary is not None, "no summary section (file not finalised)"
        for ch in summary.channels.values():
            assert ch.message_encoding == "cdr", ch
            assert "offered_qos_profiles" in ch.metadata, f"{ch.topic}: no offered_qos_profiles"
            schema = summary.schemas[ch.schema_id]
            assert schema.encoding == "ros2msg", schema
        counts = {}
        estimates = []
        for schema, channel, message, decoded in reader.iter_decoded_messages():
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            if schema.name == "friction_msgs/msg/FrictionEstimate":
                estimates.append(decoded)
            if schema.name == "friction_msgs/msg/FilmProfile":
                assert len(decoded.h_m) == len(decoded.p_pa) > 0, "empty profile"
        metadata = {m.name: m.metadata for m in reader.iter_metadata()}

    assert "friction_node" in metadata, f"metadata records: {list(metadata)}"
    config = metadata["friction_node"]["config_yaml"]
    assert "ros__parameters" in config and "contact:" in config, "config_yaml is not the resolved config"
    assert len(estimates) >= args.min_estimates, f"{len(estimates)} estimates < {args.min_estimates}"
    e = estimates[-1]
    for field in ("velocity_m_s", "load_n", "temperature_c", "friction_force_n",
                  "contact_friction_force_n", "cof", "h0_m", "h_min_m",
                  "hydrodynamic_force_n", "asperity_force_n", "asperity_load_share",
                  "regime", "status", "command_status", "calibrated_range", "iterations", "compute_time_ns",
                  "late_ns"):
        assert hasattr(e, field), f"FrictionEstimate lacks {field}"
    assert 0.0 < e.cof < 1.0 and e.h0_m > 0.0, e
    for topic in sorted(counts):
        print(f"{counts[topic]:8d}  {topic}")
    print(f"decoded {sum(counts.values())} messages; config {len(config)} bytes; last estimate "
          f"v={e.velocity_m_s:+.3f} m/s F={e.friction_force_n:+.1f} N COF={e.cof:.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
