package sogmm

// #include "sogmm/sogmm.h"
import "C"

import (
	"context"
	"runtime"
	"unsafe"
)

// Rigid registration of a point cloud or of a model to a model (issue 32;
// sogmm.h, sogmm_register_points_f32, sogmm_register_model). Options (nil = defaults): OptRegistration*,
// Threads; progress StageRegistration.

const (
	RegistrationConverged    = C.SOGMM_REGISTRATION_CONVERGED     // the pose is an estimate
	RegistrationNotConverged = C.SOGMM_REGISTRATION_NOT_CONVERGED // iterations ran out, or no point near the target
	RegistrationLowFitness   = C.SOGMM_REGISTRATION_LOW_FITNESS   // too few points explained by the target
	RegistrationDegenerate   = C.SOGMM_REGISTRATION_DEGENERATE    // some directions are unobservable
)

// Registration is what RegisterPoints and RegisterModel return
// (sogmm_registration_info).
type Registration struct {
	Pose          [16]float64 // row-major 4 x 4, source to target frame
	Status        int         // Registration* constant: check it before using Pose
	Iterations    int
	LogLikelihood float64     // mean per source point
	InlierRatio   float64     // points the mixture explains better than the outlier term
	RMSE          float64     // Mahalanobis RMS of the inliers per dimension
	Information   [36]float64 // row-major 6 x 6 observed information over (rotation, translation)
	Unobservable  int         // number of unobservable directions
	EigenRatio    float64     // smallest / largest eigenvalue of the scaled information
}

// RegisterPoints gives the rigid pose that best explains points (rows of x,
// y, z, gray in their own frame) under the model, from init (nil = identity).
// ctx and the progress func of o (StageRegistration) as Fit.
func (m *Model) RegisterPoints(ctx context.Context, points []float32, init *[16]float64, o *Options) (*Registration, error) {
	n, err := rowsOf(points, 4, "points")
	if err != nil {
		return nil, err
	}
	var pose [16]float64
	info := newRegistrationInfo()
	var initPtr *C.double
	if init != nil {
		initPtr = (*C.double)(unsafe.Pointer(&init[0]))
	}
	_, err = withProgress(ctx, o, func(o *Options) (struct{}, error) {
		return struct{}{}, m.do(o, func(p *C.sogmm_model, op *C.sogmm_options) C.sogmm_status {
			return C.sogmm_register_points_f32(p, floats(points), C.size_t(n), initPtr, op,
				(*C.double)(unsafe.Pointer(&pose[0])), &info)
		})
	})
	if err != nil {
		return nil, err
	}
	return registrationOf(pose, &info), nil
}

// RegisterModel gives the rigid pose that best explains the model source
// (e.g. a frame's own fit, in its own frame) under m: distribution to
// distribution (D2D), each source component scored by the closed-form
// overlap of its Gaussian with m's and counted as the points it stands for;
// figures per point stood for. Otherwise as RegisterPoints. A source standing
// for fewer than OptRegistrationMinPoints points is ErrInvalidData.
func (m *Model) RegisterModel(ctx context.Context, source *Model, init *[16]float64, o *Options) (*Registration, error) {
	if source == nil || source.ptr == nil {
		return nil, ErrClosed
	}
	defer runtime.KeepAlive(source)
	var pose [16]float64
	info := newRegistrationInfo()
	var initPtr *C.double
	if init != nil {
		initPtr = (*C.double)(unsafe.Pointer(&init[0]))
	}
	_, err := withProgress(ctx, o, func(o *Options) (struct{}, error) {
		return struct{}{}, m.do(o, func(p *C.sogmm_model, op *C.sogmm_options) C.sogmm_status {
			return C.sogmm_register_model(p, source.ptr, initPtr, op, (*C.double)(unsafe.Pointer(&pose[0])), &info)
		})
	})
	if err != nil {
		return nil, err
	}
	return registrationOf(pose, &info), nil
}

// newRegistrationInfo is a sogmm_registration_info sized for this binding.
func newRegistrationInfo() C.sogmm_registration_info {
	return C.sogmm_registration_info{struct_size: C.size_t(unsafe.Sizeof(C.sogmm_registration_info{}))}
}

// registrationOf is what a call wrote into info, with its pose.
func registrationOf(pose [16]float64, info *C.sogmm_registration_info) *Registration {
	r := &Registration{Pose: pose, Status: int(info.status), Iterations: int(info.iterations),
		LogLikelihood: float64(info.log_likelihood), InlierRatio: float64(info.inlier_ratio), RMSE: float64(info.rmse),
		Unobservable: int(info.unobservable), EigenRatio: float64(info.eigen_ratio)}
	for i := range r.Information {
		r.Information[i] = float64(info.information[i])
	}
	return r
}
