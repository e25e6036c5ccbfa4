#!/usr/bin/python3
"""Extracts a few real laser scans from the shared datasets into small text fixtures.

Run from the repository root with Debian's Python (it has the `rosbag` module):
    /usr/bin/python3 test/data/extract_scans.py [../shared/datasets]
Writes test/data/{fr079,intel,ccny}_scans.txt and {fr079,intel}_relations.txt (the reference relations
between scans of the consecutive blocks). Deterministic: same bags -> same files.
"""
import math
import os
import sys

import rosbag

HEADER = """# {title}
# source: {source}, topic /scan ({what})
# one scan per line:
#   stamp angle_min angle_increment range_min range_max odom_x odom_y odom_theta beam_count range_0 ... range_n-1
# odom_*: base_link in the odom frame from /odom, linearly interpolated to the scan stamp (nan: no odometry).
# ranges in metres, 3 decimals; values outside [range_min, range_max] are kept as recorded.
"""


def fmt(value, decimals=3):
    if math.isnan(value):
        return 'nan'
    if math.isinf(value):
        return 'inf' if value > 0 else '-inf'
    text = ('%.*f' % (decimals, value)).rstrip('0').rstrip('.')
    return text if text not in ('', '-0') else '0'


def read_bag(path):
    scans, odom = [], []
    with rosbag.Bag(path) as bag:
        for topic, msg, _ in bag.read_messages(topics=['/scan', '/odom']):
            if topic == '/scan':
                scans.append(msg)
            else:
                p, q = msg.pose.pose.position, msg.pose.pose.orientation
                yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
                odom.append((msg.header.stamp.to_sec(), p.x, p.y, yaw))
    scans.sort(key=lambda m: m.header.stamp.to_sec())  # a few intel scans are stored out of order
    odom.sort()
    return scans, odom


def odom_at(odom, stamp):
    if not odom or stamp < odom[0][0] or stamp > odom[-1][0]:
        return (float('nan'),) * 3
    lo, hi = 0, len(odom) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if odom[mid][0] <= stamp:
            lo = mid
        else:
            hi = mid
    a, b = odom[lo], odom[hi]
    t = 0.0 if b[0] == a[0] else (stamp - a[0]) / (b[0] - a[0])
    dth = math.atan2(math.sin(b[3] - a[3]), math.cos(b[3] - a[3]))
    th = a[3] + t * dth
    return (a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2]), math.atan2(math.sin(th), math.cos(th)))


def moving_block(scans, odom, length, min_path, min_turn):
    """First block of `length` consecutive scans whose odometry travels and turns enough."""
    poses = [odom_at(odom, s.header.stamp.to_sec()) for s in scans]
    for start in range(0, len(scans) - length, 5):
        block = poses[start:start + length]
        if any(math.isnan(p[0]) for p in block):
            continue
        path = sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(block, block[1:]))
        turn = abs(math.atan2(math.sin(block[-1][2] - block[0][2]), math.cos(block[-1][2] - block[0][2])))
        if path >= min_path and turn >= min_turn:
            return list(range(start, start + length))
    raise RuntimeError('no moving block found')


def write_relations(path, relations_path, stamps):
    """Copies the reference relations whose two stamps are both scans of the fixture."""
    def known(t):
        return any(abs(t - s) < 1e-4 for s in stamps)
    kept = []
    with open(relations_path) as relations:
        for line in relations:
            fields = line.split()
            if len(fields) == 8 and known(float(fields[0])) and known(float(fields[1])):
                kept.append(line.strip())
    with open(path, 'w') as out:
        out.write('# Kuemmerle et al. 2009 relations (t1 t2 x y z roll pitch yaw) between scans of the fixture,\n')
        out.write('# copied from %s\n' % os.path.basename(relations_path))
        for line in kept:
            out.write(line + '\n')
    print('%s: %d relations' % (path, len(kept)))


def spread(count, total, skip=0):
    step = (total - skip) // count
    return [skip + i * step + step // 2 for i in range(count)]


def write(path, title, source, what, scans, odom, indices):
    with open(path, 'w') as out:
        out.write(HEADER.format(title=title, source=source, what=what))
        for i in sorted(set(indices)):
            m = scans[i]
            stamp = m.header.stamp.to_sec()
            ox, oy, oth = odom_at(odom, stamp)
            fields = ['%.6f' % stamp, repr(float(m.angle_min)), repr(float(m.angle_increment)),
                      fmt(m.range_min, 4), fmt(m.range_max, 4), fmt(ox, 6), fmt(oy, 6), fmt(oth, 6),
                      str(len(m.ranges))] + [fmt(r) for r in m.ranges]
            out.write(' '.join(fields) + '\n')
    print('%s: %d scans, %d bytes' % (path, len(set(indices)), os.path.getsize(path)))


def main():
    datasets = sys.argv[1] if len(sys.argv) > 1 else os.path.join('..', 'shared', 'datasets')
    out_dir = os.path.dirname(os.path.abspath(__file__))

    # The two logs with reference relations: scans spread over the bag, a moving block, its relations.
    for log, geometry in (('fr079', '360 beams, 180 deg; the laser is 0.04 m ahead of base_link'),
                          ('intel', '180 beams, 180 deg; the laser is at the base origin')):
        scans, odom = read_bag(os.path.join(datasets, log, log + '.orig.bag'))
        block = moving_block(scans, odom, 20, 1.0, 0.3)
        write(os.path.join(out_dir, log + '_scans.txt'), log + ': 16 scans spread over the bag + 20 consecutive',
              log + '/' + log + '.orig.bag', geometry, scans, odom, spread(16, len(scans)) + block)
        write_relations(os.path.join(out_dir, log + '_relations.txt'), os.path.join(datasets, log, log + '.relations'),
                        [scans[i].header.stamp.to_sec() for i in block])

    scans, odom = read_bag(os.path.join(datasets, 'ccny_demo', 'laser_scan_matcher_demo.bag'))
    write(os.path.join(out_dir, 'ccny_scans.txt'), 'ccny demo: 8 scans spread over the bag (no odometry)',
          'ccny_demo/laser_scan_matcher_demo.bag', '681 beams, 239 deg, hand-held Hokuyo',
          scans, odom, spread(8, len(scans)))


if __name__ == '__main__':
    main()
