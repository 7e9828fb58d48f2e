package sogmm

import (
	"context"
	"errors"
	"math"
	"testing"
)

// Map.TrackFrame (issue 32, sogmm_map_track_frame): frames of an analytic
// room corner (floor, back wall, side wall; ray-cast per pixel as in
// tests/capi/test_map_tracking.c) go in at the poses registration finds; a
// frame of the back wall alone is degenerate and is not inserted; a bad guess
// is an error that changes nothing.

const trackW, trackH, trackF, trackCx, trackCy = 160, 120, 120.0, 79.5, 59.5

// trackTruth is 2 degrees about y, 3 cm along x and 1 cm along z.
func trackTruth() [16]float64 {
	s, c := math.Sincos(2 * math.Pi / 180)
	return [16]float64{c, 0, s, 0.03, 0, 1, 0, 0, -s, 0, c, 0.01, 0, 0, 0, 1}
}

// cornerFrame is the planes y = 0.6, z = 2.2, x = -0.9 seen from pose.
func cornerFrame(pose [16]float64, onlyWall bool) Frame {
	depth := make([]uint16, trackW*trackH)
	gray := make([]uint8, trackW*trackH)
	planes := [3][2]float64{{1, 0.6}, {2, 2.2}, {0, -0.9}}
	for v := 0; v < trackH; v++ {
		for u := 0; u < trackW; u++ {
			dc := [3]float64{(float64(u) - trackCx) / trackF, (float64(v) - trackCy) / trackF, 1}
			var d, o [3]float64
			for k := 0; k < 3; k++ {
				d[k] = pose[4*k]*dc[0] + pose[4*k+1]*dc[1] + pose[4*k+2]*dc[2]
				o[k] = pose[4*k+3]
			}
			best, hit := math.Inf(1), -1
			for k, pl := range planes {
				a := int(pl[0])
				if t := (pl[1] - o[a]) / d[a]; t > 0 && t < best {
					best, hit = t, k
				}
			}
			if hit < 0 || (onlyWall && hit != 1) {
				continue
			}
			x, y, z := o[0]+best*d[0], o[1]+best*d[1], o[2]+best*d[2]
			depth[v*trackW+u] = uint16(math.Round(best * 1000))
			gray[v*trackW+u] = uint8(128 + 100*math.Sin(6*x)*math.Cos(5*y+4*z))
		}
	}
	return Frame{Depth: depth, Gray8: gray, Width: trackW, Height: trackH, Fx: trackF, Fy: trackF, Cx: trackCx, Cy: trackCy}
}

func TestTrackFrameFollowsAKnownMotionAndRefusesAPlane(t *testing.T) {
	ctx := context.Background()
	// The geometry alone, so no odometry: the one-plane frame is judged by the
	// map only (with gray, the default, the odometry vouches for it).
	// Bandwidth 0.035 at scale 1: every fit of this map (the first frame, a
	// batch of one view, and the second frame's revisit refit) at 0.035, as
	// before the per-batch scale; at 0.05 the first frame's components reach
	// so far past the wall's edges that its slides (eigen ratio 0.002) are no
	// longer under the degeneracy ratio (tests/capi/test_map_tracking.c).
	o := mustOptions(t, Decimation(2), Bandwidth(0.035), F64(OptMapNoveltyBandwidthScale, 1), Threads(1),
		I64(OptRegistrationUseGray, 0))
	m := mustMap(t, o)
	identity := [16]float64{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}
	r, inserted, err := m.TrackFrame(ctx, cornerFrame(identity, false), nil)
	if err != nil || !inserted || r.Iterations != 0 || r.Pose != identity {
		t.Fatalf("first frame: %v %v %+v", err, inserted, r)
	}
	truth := trackTruth()
	r, inserted, err = m.TrackFrame(ctx, cornerFrame(truth, false), nil)
	if err != nil || !inserted || r.Status != RegistrationConverged {
		t.Fatalf("second frame: %v %v %+v", err, inserted, r)
	}
	// 1 mm / 1e-3 (measured 9e-5 in C on the same scene): noise-free planes.
	for k := range truth {
		if math.Abs(r.Pose[k]-truth[k]) > 1e-3 {
			t.Fatalf("pose %v, truth %v", r.Pose, truth)
		}
	}
	r, inserted, err = m.TrackFrame(ctx, cornerFrame(truth, true), &truth)
	if err != nil || inserted || r.Status != RegistrationDegenerate || r.Unobservable < 1 {
		t.Fatalf("wall: %v %v %+v", err, inserted, r)
	}
	bad := truth
	bad[0] *= 2
	if _, _, err := m.TrackFrame(ctx, cornerFrame(truth, false), &bad); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("a non-rigid guess: %v", err)
	}
	st, err := m.Stats()
	if err != nil || st.Frames != 2 {
		t.Fatalf("frames after the refusals: %v %+v", err, st)
	}
}

// TRACKING_ODOMETRY / TRACKING_MAX_DISAGREEMENT (keys 810, 811) reach the map
// through the registry: a bad bound is refused; with gray, odometry off or on,
// the second corner frame (the map accepts it) goes in at its closed-form pose.
func TestTrackFrameTrackingOptions(t *testing.T) {
	if _, err := NewOptions(F64(OptTrackingMaxDisagreement, 0)); err == nil {
		t.Fatal("a zero disagreement bound was accepted")
	}
	ctx := context.Background()
	identity := [16]float64{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}
	truth := trackTruth()
	for _, odometry := range []int64{0, 1} {
		o := mustOptions(t, Decimation(2), Bandwidth(0.05), Threads(1), I64(OptRegistrationUseGray, 1),
			I64(OptTrackingOdometry, odometry), F64(OptTrackingMaxDisagreement, 0.01))
		m := mustMap(t, o)
		if _, _, err := m.TrackFrame(ctx, cornerFrame(identity, false), nil); err != nil {
			t.Fatal(err)
		}
		r, inserted, err := m.TrackFrame(ctx, cornerFrame(truth, false), nil)
		if err != nil || !inserted {
			t.Fatalf("odometry %d: %v %v %+v", odometry, err, inserted, r)
		}
		for k := range truth {
			if math.Abs(r.Pose[k]-truth[k]) > 1e-3 {
				t.Fatalf("odometry %d: pose %v, truth %v", odometry, r.Pose, truth)
			}
		}
	}
}
