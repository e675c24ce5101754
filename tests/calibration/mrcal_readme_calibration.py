#!/usr/bin/python3
"""Runs step 4 of calibration/README.md ("Making a camera model with mrcal") on synthetic corners.

Usage: mrcal_readme_calibration.py OUTDIR

Writes OUTDIR/truth.cameramodel (a LENSMODEL_OPENCV8 camera), OUTDIR/corners.vnl (a chessboard of
10x10 corners at 0.0588 m seen in 40 poses, as mrgingham writes them, with 0.2 px Gaussian noise),
then runs the README's mrcal-calibrate-cameras command on it, which writes
OUTDIR/camera-0.cameramodel. Then, with mrcal's Python API:
- OUTDIR/difference.txt: "RMS WORST", the fitted model's projection against the truth's in
  pixels over the central 80% of the imager (mrcal.projection_diff on a 24-wide grid, after the
  rotation between the two camera frames that the board poses leave free);
- OUTDIR/projections.txt: "vx vy vz qx qy" per line, the fitted model's projection q of camera-frame
  directions v, for checking another reader of camera-0.cameramodel.
Exits non-zero when any step fails.
"""
import subprocess
import sys

import numpy as np
import mrcal

WIDTH_N, SPACING, FRAMES, NOISE_PX = 10, 0.0588, 40, 0.2
IMAGER = (1280, 1024)


def main(outdir):
    # fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6: a moderate barrel distortion.
    intrinsics = np.array([1700.0, 1690.0, 645.0, 508.0,
                           -0.12, 0.05, 0.0004, -0.0003, -0.01, 0.0, 0.0, 0.0])
    truth = mrcal.cameramodel(intrinsics=("LENSMODEL_OPENCV8", intrinsics),
                              imagersize=np.array(IMAGER))
    truth.write(f"{outdir}/truth.cameramodel")

    np.random.seed(7)
    # The board 0.9-1.3 m ahead, tilted up to about 30 degrees, moved about the view.
    q, _ = mrcal.synthesize_board_observations(
        [truth],
        object_width_n=WIDTH_N, object_height_n=WIDTH_N, object_spacing=SPACING,
        calobject_warp=None,
        rt_ref_boardcenter=np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1.1]),
        rt_ref_boardcenter__noiseradius=np.array([0.5, 0.5, 0.3, 0.25, 0.2, 0.2]),
        Nframes=FRAMES, which="all-cameras-must-see-full-board")
    q = q[:, 0] + np.random.normal(scale=NOISE_PX, size=q[:, 0].shape)

    with open(f"{outdir}/corners.vnl", "w") as corners:
        corners.write("# filename x y level\n")
        for frame in range(FRAMES):
            for corner in q[frame].reshape(-1, 2):
                corners.write(f"frame{frame:03d}.jpg {corner[0]:.4f} {corner[1]:.4f} 0\n")

    # The README's command, with the imager size that the absent images would give.
    subprocess.run(["mrcal-calibrate-cameras", "--corners-cache", "corners.vnl",
                    "--lensmodel", "LENSMODEL_OPENCV8", "--focal", "1700",
                    "--object-spacing", str(SPACING), "--object-width-n", str(WIDTH_N),
                    "--imagersize", str(IMAGER[0]), str(IMAGER[1]), "*.jpg"],
                   cwd=outdir, check=True, stdout=subprocess.DEVNULL)

    fitted = mrcal.cameramodel(f"{outdir}/camera-0.cameramodel")
    difference, _, q_grid, _ = mrcal.projection_diff((truth, fitted), gridn_width=24,
                                                     use_uncertainties=False, distance=1.1)
    central = ((q_grid[..., 0] > 0.1 * IMAGER[0]) & (q_grid[..., 0] < 0.9 * IMAGER[0]) &
               (q_grid[..., 1] > 0.1 * IMAGER[1]) & (q_grid[..., 1] < 0.9 * IMAGER[1]))
    with open(f"{outdir}/difference.txt", "w") as out:
        out.write(f"{np.sqrt(np.mean(difference[central] ** 2)):.6f} "
                  f"{difference[central].max():.6f}\n")

    v = mrcal.unproject(np.random.uniform((0, 0), IMAGER, (48, 2)), *fitted.intrinsics())
    q_fitted = mrcal.project(v, *fitted.intrinsics())
    np.savetxt(f"{outdir}/projections.txt", np.hstack((v, q_fitted)), fmt="%.12g")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
