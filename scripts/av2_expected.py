#!/usr/bin/env python3
"""Expected facts for the Argoverse 2 integration test (tests/integration/av2.rs),
computed from the Feather and map files with pyarrow and numpy alone — not
with logicrag — so the test compares two independent readings of the log.

Usage: python3 scripts/av2_expected.py > tests/data/av2_expected.json
(needs pyarrow, numpy; reads ../shared/data/av2/scenario_mining/).

Conventions (docs/formats.md, "Argoverse 2 logs"): frame i is the i-th
distinct annotation timestamp; windows are 10 frames (WindowSpec::PAPER);
the ego pose at a frame interpolates the pose file linearly (yaw unwrapped);
bearings are measured from the ego's heading, positive to the right.
"""
import glob
import json
import os
import sys

import numpy as np
import pyarrow.feather as pf

ROOT = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data", "av2", "scenario_mining")
WINDOW = 10
CAMEL = lambda c: "".join(w.capitalize() for w in c.split("_"))


def quat_yaw(qw, qx, qy, qz):
    return np.arctan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy**2 + qz**2))


def point_in_polygon(x, y, poly):
    inside = False
    n = len(poly)
    for i in range(n):
        (x1, y1), (x2, y2) = poly[i], poly[(i + 1) % n]
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            inside = not inside
    return inside


def seg_dist(px, py, a, b):
    ax, ay = a
    bx, by = b
    dx, dy = bx - ax, by - ay
    L = dx * dx + dy * dy
    t = 0.0 if L == 0 else max(0.0, min(1.0, ((px - ax) * dx + (py - ay) * dy) / L))
    return float(np.hypot(px - ax - t * dx, py - ay - t * dy))


def poly_dist(x, y, poly):
    if point_in_polygon(x, y, poly):
        return 0.0
    return min(seg_dist(x, y, poly[i], poly[(i + 1) % len(poly)]) for i in range(len(poly)))


def log_expectations(log):
    d = os.path.join(ROOT, log)
    a = pf.read_table(os.path.join(d, "annotations_with_ego.feather")).to_pandas()
    p = pf.read_table(os.path.join(d, "city_SE3_egovehicle.feather")).to_pandas()
    m = json.load(open(glob.glob(os.path.join(d, "map", "log_map_archive_*.json"))[0]))
    ts = np.sort(a.timestamp_ns.unique())
    pt = p.timestamp_ns.values
    eyaw = np.interp(ts, pt, np.unwrap(quat_yaw(p.qw, p.qx, p.qy, p.qz).values))
    ex = np.interp(ts, pt, p.tx_m.values)
    ey = np.interp(ts, pt, p.ty_m.values)
    a["f"] = np.searchsorted(ts, a.timestamp_ns.values)
    a["yaw"] = quat_yaw(a.qw, a.qx, a.qy, a.qz)
    c, s = np.cos(eyaw[a.f]), np.sin(eyaw[a.f])
    a["cx"] = ex[a.f] + c * a.tx_m - s * a.ty_m
    a["cy"] = ey[a.f] + s * a.tx_m + c * a.ty_m
    a["cyaw"] = a.yaw + eyaw[a.f]
    crossings = [
        [(q["x"], q["y"]) for q in pc["edge1"]] + [(q["x"], q["y"]) for q in reversed(pc["edge2"])]
        for pc in m["pedestrian_crossings"].values()
    ]
    objects = a[a.category != "EGO_VEHICLE"]
    out = {
        "log": log,
        "frames": int(len(ts)),
        "tracks": int(objects.track_uuid.nunique()),
        "ego_rows": int((a.category == "EGO_VEHICLE").sum()),
        "lanes": len(m["lane_segments"]),
        "crosswalks": len(m["pedestrian_crossings"]),
        "drivable_areas": len(m["drivable_areas"]),
        "types": {},
        "sides": [],
        "on_crosswalk": [],
        "far_from_crosswalks": [],
        "turns": [],
        "stationary": [],
        "travelling": [],
    }
    for uuid, g in sorted(objects.groupby("track_uuid"), key=lambda kv: kv[0]):
        g = g.sort_values("f")
        key = uuid.replace("-", "")[:8].lower()
        out["types"][key] = CAMEL(g.category.iloc[0])
        # Parked or travelling over the whole log (largest distance from the
        # first sighting, so a car that leaves and returns is not parked).
        travel = float(np.max(np.hypot(g.cx - g.cx.iloc[0], g.cy - g.cy.iloc[0])))
        if travel < 0.5:
            out["stationary"].append(key)
        elif travel > 10.0:
            out["travelling"].append(key)
        heading = np.unwrap(g.cyaw.values)
        # Labels flip a box's yaw for single frames: a running median over
        # five sightings before judging whether the heading turns one way.
        heading = np.array([np.median(heading[max(0, i - 2):i + 3]) for i in range(len(heading))])
        change = float(np.degrees(heading[-1] - heading[0]))
        monotone = np.all(np.diff(heading) * np.sign(change) > -np.radians(2.0))
        if abs(change) > 80 and monotone and travel > 10.0:
            out["turns"].append({"key": key, "turn": "TurnLeft" if change > 0 else "TurnRight",
                                 "degrees": round(change, 1)})
        for w, gw in g.groupby(g.f // WINDOW):
            first = gw.iloc[0]
            bearing = float(np.degrees(np.arctan2(-first.ty_m, first.tx_m)))
            rng = float(np.hypot(first.tx_m, first.ty_m))
            b = abs(bearing)
            side = "Front" if b <= 45 else "Behind" if b >= 135 else ("Left" if bearing < 0 else "Right")
            margin = min(abs(b - 45), abs(b - 135))
            if margin > 10 and rng < 60 and len(out["sides"]) < 400:
                out["sides"].append({"key": key, "window": int(w), "side": side, "bearing": round(bearing, 1)})
            if first.category == "PEDESTRIAN" and len(gw) >= 3:
                dists = [min(poly_dist(x, y, cw) for cw in crossings) for x, y in zip(gw.cx, gw.cy)]
                if max(dists) == 0.0:
                    out["on_crosswalk"].append({"key": key, "window": int(w)})
                elif min(dists) > 8.0:
                    out["far_from_crosswalks"].append({"key": key, "window": int(w)})
    # Keep the fixture small: a deterministic sample of bearings.
    out["sides"] = out["sides"][::7]
    return out


def main():
    logs = sorted(os.listdir(ROOT))
    logs = [l for l in logs if os.path.isdir(os.path.join(ROOT, l))]
    json.dump([log_expectations(l) for l in logs], sys.stdout, indent=1, sort_keys=True)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
