package sogmm

// #include "sogmm/sogmm.h"
import "C"

// Information keys of a model (SOGMM_INFO_*): read with InfoF64 / InfoI64;
// those .sogmm files store (the fit record and the camera) are also set
// with SetInfoF64 / SetInfoI64.
const (
	InfoSupportSize             Key = C.SOGMM_INFO_SUPPORT_SIZE
	InfoCreatedUnixMs           Key = C.SOGMM_INFO_CREATED_UNIX_MS
	InfoFitIterations           Key = C.SOGMM_INFO_FIT_ITERATIONS
	InfoFitConverged            Key = C.SOGMM_INFO_FIT_CONVERGED
	InfoFitLogLik               Key = C.SOGMM_INFO_FIT_LOG_LIKELIHOOD
	InfoFitBandwidth            Key = C.SOGMM_INFO_FIT_BANDWIDTH
	InfoFitSeed                 Key = C.SOGMM_INFO_FIT_SEED
	InfoFitNPoints              Key = C.SOGMM_INFO_FIT_N_POINTS
	InfoFitSecondsTot           Key = C.SOGMM_INFO_FIT_SECONDS_TOTAL
	InfoCameraWidth             Key = C.SOGMM_INFO_CAMERA_WIDTH
	InfoCameraHeight            Key = C.SOGMM_INFO_CAMERA_HEIGHT
	InfoCameraDecimate          Key = C.SOGMM_INFO_CAMERA_DECIMATION
	InfoFitNComponentsRequested Key = C.SOGMM_INFO_FIT_N_COMPONENTS_REQUESTED
	InfoFitTol                  Key = C.SOGMM_INFO_FIT_TOL
	InfoFitRegCovar             Key = C.SOGMM_INFO_FIT_REG_COVAR
	InfoFitMaxIter              Key = C.SOGMM_INFO_FIT_MAX_ITER
	InfoCameraFx                Key = C.SOGMM_INFO_CAMERA_FX
	InfoCameraFy                Key = C.SOGMM_INFO_CAMERA_FY
	InfoCameraCx                Key = C.SOGMM_INFO_CAMERA_CX
	InfoCameraCy                Key = C.SOGMM_INFO_CAMERA_CY
	InfoCameraDepthScale        Key = C.SOGMM_INFO_CAMERA_DEPTH_SCALE
	InfoCameraDepthMin          Key = C.SOGMM_INFO_CAMERA_DEPTH_MIN
	InfoCameraDepthMax          Key = C.SOGMM_INFO_CAMERA_DEPTH_MAX
)

// SetInfoF64 sets an f64 information key that .sogmm files store (the fit
// record, InfoFit*, or the camera, InfoCamera*), e.g. to give a model rebuilt
// with FromArrays the provenance of its fit; a model without that record gets
// one with the format's defaults first. A key files do not store, or a value
// the format cannot hold (non-finite), gives ErrInvalidArg naming the key,
// the model unchanged. Needs exclusive use of m.
func (m *Model) SetInfoF64(key Key, v float64) error {
	return m.do(nil, func(p *C.sogmm_model, _ *C.sogmm_options) C.sogmm_status {
		return C.sogmm_model_set_info_f64(p, C.sogmm_key(key), C.double(v))
	})
}

// SetInfoI64 is SetInfoF64 for i64 keys (InfoFitConverged 0 or 1, int32
// fields in range, InfoCameraDecimate >= 1, ...; InfoFitSeed takes the
// uint64's bits). Needs exclusive use of m.
func (m *Model) SetInfoI64(key Key, v int64) error {
	return m.do(nil, func(p *C.sogmm_model, _ *C.sogmm_options) C.sogmm_status {
		return C.sogmm_model_set_info_i64(p, C.sogmm_key(key), C.int64_t(v))
	})
}
