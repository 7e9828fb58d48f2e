package sogmm

// #include "sogmm/sogmm.h"
import "C"

import (
	"context"
	"unsafe"
)

// TrackFrame inserts an RGB-D frame at the camera-to-world pose that
// registration to the map finds (issue 32; sogmm_map_track_frame): from guess,
// or (nil) the constant-velocity prediction from the map's last two frames;
// the map's first frame goes in at the guess (nil: identity). Registration
// options are the map's creation options (OptRegistration*, OptTracking*). The
// frame is inserted when the registration's Status is RegistrationConverged or,
// with OptRegistrationUseGray and OptTrackingOdometry, when its registration to
// the last tracked frame vouches for it (sogmm.h states the rule); inserted says
// whether it was, the Registration's Pose is the pose used (or the map
// registration's last iterate) and its figures are the map registration's. The first frame reports RegistrationConverged with 0
// iterations. ctx and progress as InsertPoints.
func (m *Map) TrackFrame(ctx context.Context, f Frame, guess *[16]float64) (r *Registration, inserted bool, err error) {
	h, err := f.handle()
	if err != nil {
		return nil, false, err
	}
	defer C.sogmm_frame_free(h)
	var pose [16]float64
	var in C.int32_t
	info := newRegistrationInfo()
	var guessPtr *C.double
	if guess != nil {
		guessPtr = (*C.double)(unsafe.Pointer(&guess[0]))
	}
	err = m.change(ctx, "TrackFrame", func(p *C.sogmm_map) C.sogmm_status {
		return C.sogmm_map_track_frame(p, h, guessPtr, (*C.double)(unsafe.Pointer(&pose[0])), &in, &info)
	})
	if err != nil {
		return nil, false, err
	}
	return registrationOf(pose, &info), in != 0, nil
}
