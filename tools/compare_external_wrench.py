#!/usr/bin/env python3
"""RMS error of process_bag's estimated contact wrench against the bag's applied one.

usage: /usr/bin/python3 tools/compare_external_wrench.py BAG.bag LOADS.csv [LINK] [TOPIC]

BAG: made by make_example_bag --effort --sensor-frame LINK (its TOPIC, default
/ft_sensor/wrench, is the wrench applied at LINK: the truth, not given to the estimator);
LOADS.csv: process_bag --csv with external_effort/contacts [{link: LINK}]. Compares
external@LINK.fx .. .mz with the truth at the same stamps, skipping the first 0.5 s
(the observer's start). docs/external_loads.md, "External torques and contact wrenches".
"""
import csv
import math
import sys

import rosbag


def main():
    bag, loads = sys.argv[1], sys.argv[2]
    link = sys.argv[3] if len(sys.argv) > 3 else "panda_hand_tcp"
    topic = sys.argv[4] if len(sys.argv) > 4 else "/ft_sensor/wrench"
    truth = {}
    for _, msg, _ in rosbag.Bag(bag).read_messages(topics=[topic]):
        w = msg.wrench
        truth[round(msg.header.stamp.to_sec(), 6)] = (
            w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z)
    rows = list(csv.DictReader(open(loads)))
    t0 = float(rows[0]["t"])
    ef = em = mag = contact = 0.0
    n = 0
    for r in rows:
        t = float(r["t"])
        key = round(t, 6)
        if key not in truth or t - t0 < 0.5:
            continue
        est = [float(r["external@%s.%s" % (link, c)]) for c in ("fx", "fy", "fz", "mx", "my", "mz")]
        tr = truth[key]
        ef += sum((est[i] - tr[i]) ** 2 for i in range(3))
        em += sum((est[i] - tr[i]) ** 2 for i in range(3, 6))
        mag += sum(tr[i] ** 2 for i in range(3))
        contact += float(r["contact"])
        n += 1
    if n == 0:
        sys.exit("no common stamps")
    print("samples %d, RMS |F| %.3f N, RMS force error %.3f N, RMS moment error %.4f N m, "
          "in contact %.3f of the samples" % (n, math.sqrt(mag / n), math.sqrt(ef / n),
                                              math.sqrt(em / n), contact / n))


if __name__ == "__main__":
    main()
