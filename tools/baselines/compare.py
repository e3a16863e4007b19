#!/usr/bin/env python3
"""Register simulated map pairs with mapmerge and with the pipelines it is compared with.

The cases are those `cargo xtask gen` writes (case_*/robot_0.yaml, robot_1.yaml and
truth.json): A is robot 0, B is robot 1, and the truth is the pair (a=0, b=1) of truth.json.
Every method reads the same map_server files, so mapmerge runs through its binary exactly as
a user (or an outside test) runs it.

Methods:
  mapmerge   `mapmerge estimate A B --json`: exit 0 is an answer, exit 3 a decline.
  ros-akaze  The pipeline of the ROS package multirobot_map_merge (m-explore, combine_grids):
             the grid's raw values as an 8-bit image (free 0, occupied 100, unknown 255, as
             the package feeds nav_msgs/OccupancyGrid data to OpenCV), AKAZE features (its
             default `estimation_feature_type`), OpenCV's best-of-2-nearest matching with
             match_conf 0.3 in both directions, `estimateAffinePartial2D` (RANSAC, 3 px),
             and the pair kept when its confidence, inliers / (8 + 0.3 matches), reaches 1.0
             (its default `estimation_confidence`). Fewer than 6 matches: no estimate.
  ros-orb    The same with ORB features (`estimation_feature_type: orb`; OpenCV defaults).
  sift-0.65  The research paper's intensity pipeline with OpenCV's SIFT (default settings) on
             the map_server image (free 254, unknown 205, occupied 0), Lowe's ratio 0.65 from
             B to A, `estimateAffinePartial2D` (RANSAC, 3 px), and the same confidence rule
             to decide acceptance (the paper keeps the best hypothesis; without some rule no
             pair would ever be declined).

  carpin     Carpin's Hough-spectrum map merging (Autonomous Robots 2008), as published: the
             Hough spectra of both maps' occupied cells (1-degree bins over a half turn, the
             sum of squared accumulator counts per angle), their circular cross-correlation's
             3 highest local maxima, each angle and the angle plus a half turn as rotation
             candidates; per candidate the translation from the cross-correlations of the
             occupied cells' projections (B turned) on the normal of A's strongest line
             direction and on its perpendicular, and of the candidates the
             one with the highest acceptance index (Birk and Carpin) is the answer. The
             method always answers, so it never declines a pair.

The feature-based baselines estimate a similarity (rotation, translation, scale), as the ROS package does;
their error is measured with the transform as estimated, scale included. Their estimate is
scored even when their confidence rule declines it: the column "within 3 px, any confidence"
says how many pairs always answering would have registered (on pairs that overlap). mapmerge
reports no transform for a declined pair, so for it that column counts its successes.

Metrics follow the project's conventions: displacement error is the mean, over B's known
cells p, of |T_est(p) - T_true(p)| in pixels; success is an accepted answer within 3 px; on a
pair generated without overlap (truth.json's requested_overlap is 0) success is a decline.

Needs Python 3.8+, numpy and OpenCV with AKAZE, ORB and SIFT in its main module, e.g.
`pip install numpy opencv-python-headless==4.10.0.84` (OpenCV 5 moved AKAZE out of it).

Example (from the repository root):
  cargo build --release -p mapmerge
  cargo xtask gen --preset disaster --overlap 0.3 --noise 0.1 --seed 7000000 --count 20 \\
      --out target/compare/disaster_30
  python3 tools/baselines/compare.py target/compare/disaster_30 --out target/compare/d30.jsonl
"""

import argparse
import json
import math
import statistics
import subprocess
import sys
import time
from pathlib import Path

try:
    import cv2
    import numpy as np
except ImportError as e:  # pragma: no cover - depends on the machine
    sys.exit(f"compare.py needs numpy and OpenCV ({e}); see the module docstring")

METHODS = ["mapmerge", "ros-akaze", "ros-orb", "sift-0.65", "carpin"]
SUCCESS_PX = 3.0


def read_map(yaml_path):
    """The occupancy class per cell, map_server's way: 0 free, 1 occupied, 2 unknown."""
    meta = {}
    for line in Path(yaml_path).read_text().splitlines():
        if ":" in line:
            key, value = line.split(":", 1)
            meta[key.strip()] = value.strip()
    image_path = Path(yaml_path).parent / meta["image"]
    img = cv2.imread(str(image_path), cv2.IMREAD_GRAYSCALE)
    if img is None:
        raise ValueError(f"{image_path}: cannot read the image")
    v = img.astype(np.float64)
    p = v / 255.0 if meta.get("negate", "0") in ("1", "true") else (255.0 - v) / 255.0
    occ = float(meta.get("occupied_thresh", 0.65))
    free = float(meta.get("free_thresh", 0.196))
    cls = np.full(img.shape, 2, np.uint8)
    cls[p > occ] = 1
    cls[p < free] = 0
    return cls


def ros_image(cls):
    """The grid as the ROS package hands it to OpenCV: int8 data read as uint8."""
    out = np.full(cls.shape, 255, np.uint8)
    out[cls == 0] = 0
    out[cls == 1] = 100
    return out


def map_server_image(cls):
    out = np.full(cls.shape, 205, np.uint8)
    out[cls == 0] = 254
    out[cls == 1] = 0
    return out


def best_of_2_nearest(desc_b, desc_a, norm, match_conf):
    """OpenCV stitching's matching: a nearest neighbour counts when it is closer than
    (1 - match_conf) times the second nearest, in either direction (union, no duplicates)."""
    if desc_b is None or desc_a is None or len(desc_b) < 2 or len(desc_a) < 2:
        return []
    bf = cv2.BFMatcher(norm)
    ratio = 1.0 - match_conf
    found, seen = [], set()
    for m in bf.knnMatch(desc_b, desc_a, k=2):
        if len(m) == 2 and m[0].distance < ratio * m[1].distance:
            found.append((m[0].queryIdx, m[0].trainIdx))
            seen.add((m[0].queryIdx, m[0].trainIdx))
    for m in bf.knnMatch(desc_a, desc_b, k=2):
        if len(m) == 2 and m[0].distance < ratio * m[1].distance:
            pair = (m[0].trainIdx, m[0].queryIdx)
            if pair not in seen:
                found.append(pair)
                seen.add(pair)
    return found


def ratio_matches(desc_b, desc_a, norm, ratio):
    """Lowe's ratio test from B to A only, as the paper describes it."""
    if desc_b is None or desc_a is None or len(desc_b) < 1 or len(desc_a) < 2:
        return []
    bf = cv2.BFMatcher(norm)
    return [
        (m[0].queryIdx, m[0].trainIdx)
        for m in bf.knnMatch(desc_b, desc_a, k=2)
        if len(m) == 2 and m[0].distance < ratio * m[1].distance
    ]


def opencv_pipeline(img_a, img_b, detector, norm, matcher):
    """(accepted, 2x3 B->A matrix or None, details)."""
    kp_a, desc_a = detector.detectAndCompute(img_a, None)
    kp_b, desc_b = detector.detectAndCompute(img_b, None)
    matches = matcher(desc_b, desc_a, norm)
    details = {"keypoints": [len(kp_a), len(kp_b)], "matches": len(matches)}
    if len(matches) < 6:
        details["reason"] = "fewer than 6 matches"
        return False, None, details
    src = np.float32([kp_b[i].pt for i, _ in matches]).reshape(-1, 1, 2)
    dst = np.float32([kp_a[j].pt for _, j in matches]).reshape(-1, 1, 2)
    m, mask = cv2.estimateAffinePartial2D(
        src, dst, method=cv2.RANSAC, ransacReprojThreshold=3.0, maxIters=2000,
        confidence=0.99, refineIters=10)
    if m is None:
        details["reason"] = "no transform"
        return False, None, details
    inliers = int(mask.sum()) if mask is not None else 0
    confidence = inliers / (8 + 0.3 * len(matches))
    details.update(inliers=inliers, confidence=confidence)
    return confidence >= 1.0, m, details


def hough_spectrum(xs, ys, bins):
    """Per line-normal angle (bins over [0, pi)), the sum of squared Hough accumulator counts
    over the distances, normalised to unit length."""
    out = np.zeros(bins)
    for k in range(bins):
        t = math.pi * k / bins
        rho = np.rint(xs * math.cos(t) + ys * math.sin(t)).astype(np.int64)
        counts = np.bincount(rho - rho.min())
        out[k] = float(np.dot(counts, counts))
    norm = np.linalg.norm(out)
    return out / norm if norm > 0 else out


def best_shift(a, b):
    """The shift s maximising sum_n a[n + s] b[n] (full cross-correlation)."""
    c = np.correlate(a, b, mode="full")
    return int(np.argmax(c)) - (len(b) - 1)


def acceptance_index(m, cls_a, cls_b):
    """Birk and Carpin's agree / (agree + disagree) over B's known cells that B->A matrix `m`
    puts on known cells of A (free against occupied disagrees)."""
    ys, xs = np.nonzero(cls_b != 2)
    qx = np.rint(m[0, 0] * xs + m[0, 1] * ys + m[0, 2]).astype(np.int64)
    qy = np.rint(m[1, 0] * xs + m[1, 1] * ys + m[1, 2]).astype(np.int64)
    h, w = cls_a.shape
    inside = (qx >= 0) & (qy >= 0) & (qx < w) & (qy < h)
    a = cls_a[qy[inside], qx[inside]]
    b = cls_b[ys[inside], xs[inside]]
    known = a != 2
    agree = int(np.sum(a[known] == b[known]))
    disagree = int(np.sum(known)) - agree
    return agree / (agree + disagree) if agree + disagree else 0.0


def run_carpin(cls_a, cls_b, bins=180, peaks=3):
    ya, xa = np.nonzero(cls_a == 1)
    yb, xb = np.nonzero(cls_b == 1)
    details = {"occupied": [len(xa), len(xb)]}
    if len(xa) < 2 or len(xb) < 2:
        details["reason"] = "too few occupied cells"
        return False, None, details
    xa, ya, xb, yb = (v.astype(np.float64) for v in (xa, ya, xb, yb))
    sa, sb = hough_spectrum(xa, ya, bins), hough_spectrum(xb, yb, bins)
    # B turned by theta has the spectrum of B shifted by theta: A(phi) ~ B(phi - theta).
    cc = np.array([float(np.dot(sa, np.roll(sb, k))) for k in range(bins)])
    maxima = [k for k in range(bins) if cc[k] >= cc[k - 1] and cc[k] > cc[(k + 1) % bins]]
    maxima.sort(key=lambda k: -cc[k])
    # Translations from projections along A's dominant line normal and across it, where the
    # walls of a building project to sharp peaks.
    phi = math.pi * int(np.argmax(sa)) / bins
    axes = [np.array([math.cos(phi), math.sin(phi)]), np.array([-math.sin(phi), math.cos(phi)])]
    best = None
    for k in maxima[:peaks]:
        for theta in (math.pi * k / bins, math.pi * k / bins + math.pi):
            c, s = math.cos(theta), math.sin(theta)
            xr, yr = c * xb - s * yb, s * xb + c * yb
            t = np.zeros(2)
            for u in axes:
                pa, pr = xa * u[0] + ya * u[1], xr * u[0] + yr * u[1]
                lo_a, lo_r = math.floor(pa.min()), math.floor(pr.min())
                proj_a = np.bincount(np.rint(pa - lo_a).astype(np.int64))
                proj_b = np.bincount(np.rint(pr - lo_r).astype(np.int64))
                t += (best_shift(proj_a, proj_b) + lo_a - lo_r) * u
            m = np.array([[c, -s, t[0]], [s, c, t[1]]], dtype=np.float64)
            ai = acceptance_index(m, cls_a, cls_b)
            if best is None or ai > best[0]:
                best = (ai, m)
    if best is None:
        details["reason"] = "no spectrum peak"
        return False, None, details
    details["acceptance_index"] = best[0]
    return True, best[1], details


def run_baseline(method, case):
    cls_a = read_map(case / "robot_0.yaml")
    cls_b = read_map(case / "robot_1.yaml")
    if method == "carpin":
        return run_carpin(cls_a, cls_b)
    if method == "ros-akaze":
        det, norm = cv2.AKAZE_create(), cv2.NORM_HAMMING
        img_a, img_b = ros_image(cls_a), ros_image(cls_b)
        matcher = lambda b, a, n: best_of_2_nearest(b, a, n, 0.3)  # noqa: E731
    elif method == "ros-orb":
        det, norm = cv2.ORB_create(), cv2.NORM_HAMMING
        img_a, img_b = ros_image(cls_a), ros_image(cls_b)
        matcher = lambda b, a, n: best_of_2_nearest(b, a, n, 0.3)  # noqa: E731
    elif method == "sift-0.65":
        det, norm = cv2.SIFT_create(), cv2.NORM_L2
        img_a, img_b = map_server_image(cls_a), map_server_image(cls_b)
        matcher = lambda b, a, n: ratio_matches(b, a, n, 0.65)  # noqa: E731
    else:
        raise ValueError(method)
    return opencv_pipeline(img_a, img_b, det, norm, matcher)


def run_mapmerge(binary, case):
    proc = subprocess.run(
        [binary, "estimate", str(case / "robot_0.yaml"), str(case / "robot_1.yaml"), "--json"],
        capture_output=True, text=True)
    if proc.returncode not in (0, 3):
        raise RuntimeError(f"{case}: mapmerge exited {proc.returncode}: {proc.stderr.strip()}")
    out = json.loads(proc.stdout)
    if proc.returncode == 3:
        return False, None, {"reason": out.get("reason")}
    t = out["transform"]
    c, s = math.cos(t["theta"]), math.sin(t["theta"])
    m = np.array([[c, -s, t["tx"]], [s, c, t["ty"]]])
    return True, m, {"confidence": out.get("confidence"), "hypothesis": out.get("hypothesis")}


def errors(m, truth, cls_b):
    """(rotation error in degrees, mean displacement over B's known cells in px)."""
    ys, xs = np.nonzero(cls_b != 2)
    pts = np.stack([xs, ys]).astype(np.float64)
    c, s = math.cos(truth["theta"]), math.sin(truth["theta"])
    true_pts = np.array([[c, -s], [s, c]]) @ pts + np.array([[truth["tx"]], [truth["ty"]]])
    est_pts = m[:, :2] @ pts + m[:, 2:3]
    disp = float(np.mean(np.hypot(*(est_pts - true_pts))))
    d = math.degrees(math.atan2(m[1, 0], m[0, 0]) - truth["theta"])
    rot = abs((d + 180.0) % 360.0 - 180.0)
    return rot, disp


def cases_in(path):
    path = Path(path)
    if (path / "truth.json").exists():
        return [path]
    found = sorted((p for p in path.glob("case_*") if (p / "truth.json").exists()),
                   key=lambda p: int(p.name.split("_")[1]))
    if not found:
        sys.exit(f"{path}: no case (a folder with truth.json, or case_* folders holding one)")
    return found


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dirs", nargs="+", help="case folders, or folders of case_* folders")
    ap.add_argument("--methods", default=",".join(METHODS),
                    help=f"comma-separated, of {', '.join(METHODS)} (default: all)")
    ap.add_argument("--mapmerge", default="target/release/mapmerge",
                    help="the mapmerge binary (default: target/release/mapmerge)")
    ap.add_argument("--out", help="write one JSON line per case and method here")
    args = ap.parse_args()
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    for m in methods:
        if m not in METHODS:
            sys.exit(f"unknown method {m!r} (known: {', '.join(METHODS)})")
    if "mapmerge" in methods and not Path(args.mapmerge).exists():
        sys.exit(f"{args.mapmerge}: no such binary (cargo build --release -p mapmerge)")

    records = []
    for d in args.dirs:
        for case in cases_in(d):
            truth_doc = json.loads((case / "truth.json").read_text())
            truth = next(p["transform"] for p in truth_doc["pairs"] if (p["a"], p["b"]) == (0, 1))
            overlap = truth_doc["achieved_overlap"]
            # The zero-overlap rows allow a sliver (at most 2 % in `cargo xtask eval`): what
            # was asked for decides.
            no_overlap = truth_doc["requested_overlap"] <= 0.0
            cls_b = read_map(case / "robot_1.yaml")
            for method in methods:
                t0 = time.perf_counter()
                if method == "mapmerge":
                    accepted, m, details = run_mapmerge(args.mapmerge, case)
                else:
                    accepted, m, details = run_baseline(method, case)
                ms = 1000.0 * (time.perf_counter() - t0)
                # The baselines' estimate is scored whether or not their confidence rule kept
                # it: `within_3px_any` says what always answering would have given.
                rot = disp = None
                if m is not None:
                    rot, disp = errors(m, truth, cls_b)
                if not accepted:
                    details["declined_error_px"] = disp
                    rot = disp = None
                success = (not accepted) if no_overlap else (accepted and disp <= SUCCESS_PX)
                raw = details.get("declined_error_px", disp)
                within_any = (not no_overlap) and raw is not None and raw <= SUCCESS_PX
                rec = {"set": str(d), "case": case.name, "method": method,
                       "within_3px_any": within_any,
                       "achieved_overlap": overlap, "accepted": accepted, "success": success,
                       "rotation_error_deg": rot, "displacement_error_px": disp,
                       "millis": ms, "details": details}
                records.append(rec)
                print(f"{case} {method}: "
                      + (f"accepted, {disp:.2f} px, {rot:.2f} deg" if accepted else "declined")
                      + f" ({ms:.0f} ms)", file=sys.stderr)
    if args.out:
        # Written beside, then renamed: a reader never sees half a file.
        tmp = Path(args.out).with_name(f".{Path(args.out).name}.tmp")
        tmp.write_text("".join(json.dumps(r) + "\n" for r in records))
        tmp.replace(args.out)

    print("| cases | method | pairs | success | accepted | false accepts "
          "| within 3 px, any confidence | median rot. err (deg) | median disp. err (px) "
          "| mean time (ms) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for d in args.dirs:
        for method in methods:
            rs = [r for r in records if r["set"] == str(d) and r["method"] == method]
            n = len(rs)
            acc = [r for r in rs if r["accepted"]]
            pct = lambda k: f"{100.0 * k / n:.0f}%" if n else "-"  # noqa: E731
            # The upper median, as `cargo xtask eval` reports it.
            med = lambda key: (f"{sorted(r[key] for r in acc)[len(acc) // 2]:.2f}"  # noqa: E731
                               if acc else "-")
            print(f"| {d} | {method} | {n} | {pct(sum(r['success'] for r in rs))} "
                  f"| {pct(len(acc))} | {pct(sum(r['accepted'] and not r['success'] for r in rs))} "
                  f"| {pct(sum(r['within_3px_any'] for r in rs))} "
                  f"| {med('rotation_error_deg')} | {med('displacement_error_px')} "
                  f"| {statistics.mean(r['millis'] for r in rs):.0f} |")


if __name__ == "__main__":
    main()
