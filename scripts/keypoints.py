"""2-D keypoints (and person masks) of a video from MediaPipe Pose, in the
layout `imitate track --keypoints` reads (docs/formats.md, "Keypoints").

    bash scripts/keypoints.sh VIDEO OUT.csv|OUT.json [--masks DIR]

(the shell wrapper installs mediapipe==0.10.21 into a virtual environment
first). MediaPipe Pose runs with model complexity 1 and segmentation on,
as the project's reference; the person mask of each frame goes to
DIR/NNNNNN.png (255 where MediaPipe's mask is above 0.5) when --masks is
given. Prints the frames read and MediaPipe's own frames a second.
"""

import argparse
import json
import math
import os
import sys
import time

# MediaPipe Pose's 33 landmarks, in its order.
LANDMARKS = [
    "nose", "left_eye_inner", "left_eye", "left_eye_outer", "right_eye_inner",
    "right_eye", "right_eye_outer", "left_ear", "right_ear", "mouth_left",
    "mouth_right", "left_shoulder", "right_shoulder", "left_elbow",
    "right_elbow", "left_wrist", "right_wrist", "left_pinky", "right_pinky",
    "left_index", "right_index", "left_thumb", "right_thumb", "left_hip",
    "right_hip", "left_knee", "right_knee", "left_ankle", "right_ankle",
    "left_heel", "right_heel", "left_foot_index", "right_foot_index",
]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("video")
    parser.add_argument("out", help="the keypoints file: .csv or .json")
    parser.add_argument("--masks", metavar="DIR", help="also write each frame's person mask as DIR/NNNNNN.png")
    args = parser.parse_args()
    kind = os.path.splitext(args.out)[1].lower()
    if kind not in (".csv", ".json"):
        sys.exit(f"{args.out}: the keypoints file must end in .csv or .json")

    import cv2
    import mediapipe as mp

    capture = cv2.VideoCapture(args.video)
    if not capture.isOpened():
        sys.exit(f"{args.video}: not a readable video")
    fps = capture.get(cv2.CAP_PROP_FPS) or None
    if args.masks:
        os.makedirs(args.masks, exist_ok=True)

    frames = []
    width = height = None
    spent = 0.0
    with mp.solutions.pose.Pose(
        static_image_mode=False, model_complexity=1, enable_segmentation=True, min_detection_confidence=0.5
    ) as pose:
        while True:
            ok, bgr = capture.read()
            if not ok:
                break
            height, width = bgr.shape[:2]
            rgb = cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
            start = time.perf_counter()
            result = pose.process(rgb)
            spent += time.perf_counter() - start
            points = None
            if result.pose_landmarks is not None:
                points = [
                    (p.x * width, p.y * height, p.visibility) for p in result.pose_landmarks.landmark
                ]
            frames.append(points)
            if args.masks:
                mask = result.segmentation_mask
                image = (mask > 0.5).astype("uint8") * 255 if mask is not None else rgb[:, :, 0] * 0
                cv2.imwrite(os.path.join(args.masks, f"{len(frames) - 1:06}.png"), image)
    if not frames:
        sys.exit(f"{args.video}: no frame could be read")

    staging = args.out + ".partial"
    try:
        with open(staging, "w") as out:
            if kind == ".csv":
                write_csv(out, frames)
            else:
                write_json(out, frames, width, height, fps)
        os.replace(staging, args.out)
    except OSError as error:
        if os.path.exists(staging):
            os.remove(staging)
        sys.exit(f"{args.out}: cannot write: {error.strerror}")
    found = sum(points is not None for points in frames)
    rate = len(frames) / spent if spent > 0 else math.inf
    print(f"{args.video}: {len(frames)} frames, a person in {found}; MediaPipe Pose at {rate:.1f} frames/s → {args.out}")


def write_csv(out, frames):
    out.write("frame,joint,x,y,confidence\n")
    for k, points in enumerate(frames):
        for j, name in enumerate(LANDMARKS):
            if points is None:
                out.write(f"{k},{name},,,0\n")
            else:
                x, y, c = points[j]
                out.write(f"{k},{name},{x:.2f},{y:.2f},{c:.4f}\n")


def write_json(out, frames, width, height, fps):
    document = {
        "layout": "mediapipe",
        "width": width,
        "height": height,
        "fps": fps,
        "joints": LANDMARKS,
        "frames": [
            None if points is None else [[round(x, 2), round(y, 2), round(c, 4)] for x, y, c in points]
            for points in frames
        ],
    }
    json.dump(document, out)
    out.write("\n")


if __name__ == "__main__":
    main()
