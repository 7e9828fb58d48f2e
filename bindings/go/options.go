package sogmm

// #include "sogmm/sogmm.h"
import "C"

import "runtime"

// Key names an option (SOGMM_OPT_*) or a model information value (SOGMM_INFO_*).
type Key int32

// BEGIN GENERATED option keys (tools/options/regenerate.py, from core/src/option_table.cpp)

// Option keys: the C macros by their Go names (types, ranges, defaults and
// meaning: sogmm.h, spec/api.md, or OptionInfoOf at run time).
const (
	OptBandwidth                   Key = C.SOGMM_OPT_BANDWIDTH
	OptNComponents                 Key = C.SOGMM_OPT_N_COMPONENTS
	OptTol                         Key = C.SOGMM_OPT_TOL
	OptRegCovar                    Key = C.SOGMM_OPT_REG_COVAR
	OptMaxIter                     Key = C.SOGMM_OPT_MAX_ITER
	OptSeed                        Key = C.SOGMM_OPT_SEED
	OptThreads                     Key = C.SOGMM_OPT_THREADS
	OptModeCounter                 Key = C.SOGMM_OPT_MODE_COUNTER
	OptTruncationNats              Key = C.SOGMM_OPT_TRUNCATION_NATS
	OptNInit                       Key = C.SOGMM_OPT_N_INIT
	OptDequantiseDepth             Key = C.SOGMM_OPT_DEQUANTISE_DEPTH
	OptEmAcceleration              Key = C.SOGMM_OPT_EM_ACCELERATION
	OptTolStandardErrors           Key = C.SOGMM_OPT_TOL_STANDARD_ERRORS
	OptWarmMaxIter                 Key = C.SOGMM_OPT_WARM_MAX_ITER
	OptDepthScale                  Key = C.SOGMM_OPT_DEPTH_SCALE
	OptDepthMin                    Key = C.SOGMM_OPT_DEPTH_MIN
	OptDepthMax                    Key = C.SOGMM_OPT_DEPTH_MAX
	OptDecimation                  Key = C.SOGMM_OPT_DECIMATION
	OptZstdLevel                   Key = C.SOGMM_OPT_ZSTD_LEVEL
	OptFloat64                     Key = C.SOGMM_OPT_FLOAT64
	OptCompress                    Key = C.SOGMM_OPT_COMPRESS
	OptArrayPrecision              Key = C.SOGMM_OPT_ARRAY_PRECISION
	OptMaxDecodedBytes             Key = C.SOGMM_OPT_MAX_DECODED_BYTES
	OptVerifyChecksums             Key = C.SOGMM_OPT_VERIFY_CHECKSUMS
	OptSampleTruncation            Key = C.SOGMM_OPT_SAMPLE_TRUNCATION
	OptQueryTruncationNats         Key = C.SOGMM_OPT_QUERY_TRUNCATION_NATS
	OptRenderSurfaceSigma          Key = C.SOGMM_OPT_RENDER_SURFACE_SIGMA
	OptMapNovelty                  Key = C.SOGMM_OPT_MAP_NOVELTY
	OptMapNoveltyThreshold         Key = C.SOGMM_OPT_MAP_NOVELTY_THRESHOLD
	OptMapBatchSize                Key = C.SOGMM_OPT_MAP_BATCH_SIZE
	OptMapFusion                   Key = C.SOGMM_OPT_MAP_FUSION
	OptMapFusionMethod             Key = C.SOGMM_OPT_MAP_FUSION_METHOD
	OptMapFusionThreshold          Key = C.SOGMM_OPT_MAP_FUSION_THRESHOLD
	OptMapWarmStart                Key = C.SOGMM_OPT_MAP_WARM_START
	OptMapNoveltyBandwidthScale    Key = C.SOGMM_OPT_MAP_NOVELTY_BANDWIDTH_SCALE
	OptMapRevisitRefitRatio        Key = C.SOGMM_OPT_MAP_REVISIT_REFIT_RATIO
	OptMapDeltaHistory             Key = C.SOGMM_OPT_MAP_DELTA_HISTORY
	OptMapFreeSpaceCarve           Key = C.SOGMM_OPT_MAP_FREE_SPACE_CARVE
	OptMapComponentPrecision       Key = C.SOGMM_OPT_MAP_COMPONENT_PRECISION
	OptOccupancySigma              Key = C.SOGMM_OPT_OCCUPANCY_SIGMA
	OptOccupancyThickness          Key = C.SOGMM_OPT_OCCUPANCY_THICKNESS
	OptSurfaceDiscSigmas           Key = C.SOGMM_OPT_SURFACE_DISC_SIGMAS
	OptRegistrationMaxIter         Key = C.SOGMM_OPT_REGISTRATION_MAX_ITER
	OptRegistrationTol             Key = C.SOGMM_OPT_REGISTRATION_TOL
	OptRegistrationOutlierRatio    Key = C.SOGMM_OPT_REGISTRATION_OUTLIER_RATIO
	OptRegistrationUseGray         Key = C.SOGMM_OPT_REGISTRATION_USE_GRAY
	OptRegistrationLevels          Key = C.SOGMM_OPT_REGISTRATION_LEVELS
	OptRegistrationCoarseSigma     Key = C.SOGMM_OPT_REGISTRATION_COARSE_SIGMA
	OptRegistrationMinInlierRatio  Key = C.SOGMM_OPT_REGISTRATION_MIN_INLIER_RATIO
	OptRegistrationDegeneracyRatio Key = C.SOGMM_OPT_REGISTRATION_DEGENERACY_RATIO
	OptRegistrationMinPoints       Key = C.SOGMM_OPT_REGISTRATION_MIN_POINTS
	OptRegistrationDepthNoise      Key = C.SOGMM_OPT_REGISTRATION_DEPTH_NOISE
	OptTrackingOdometry            Key = C.SOGMM_OPT_TRACKING_ODOMETRY
	OptTrackingMaxDisagreement     Key = C.SOGMM_OPT_TRACKING_MAX_DISAGREEMENT
)

// END GENERATED option keys

// Options is an owned sogmm_options handle: parameters for fit, save, load
// and sample. A nil *Options passed to any function means "all defaults".
type Options struct {
	ptr      *C.sogmm_options
	progress ProgressFunc // OnProgress; Go-side, installed per call (withProgress)
}

// Option sets one value; the library checks its range (ErrInvalidArg with a
// message naming the key).
type Option func(*Options) error

// NewOptions creates a handle with every default, then applies opts in order.
func NewOptions(opts ...Option) (*Options, error) {
	if err := abiOnce(); err != nil {
		return nil, err
	}
	o := &Options{}
	// Out through a local: cgo refuses a pointer into a struct that holds Go
	// pointers (the progress func).
	var ptr *C.sogmm_options
	if err := call(func() C.sogmm_status { return C.sogmm_options_create(&ptr) }); err != nil {
		return nil, err
	}
	o.ptr = ptr
	runtime.SetFinalizer(o, (*Options).Close)
	if err := o.Set(opts...); err != nil {
		o.Close()
		return nil, err
	}
	return o, nil
}

// Set applies opts in order and stops at the first refused value.
func (o *Options) Set(opts ...Option) error {
	for _, set := range opts {
		if err := set(o); err != nil {
			return err
		}
	}
	return nil
}

// Close frees the handle. It is idempotent; it must not race with other calls.
func (o *Options) Close() {
	if o == nil || o.ptr == nil {
		return
	}
	runtime.SetFinalizer(o, nil)
	C.sogmm_options_free(o.ptr)
	o.ptr = nil
}

func (o *Options) raw() (*C.sogmm_options, error) {
	if o == nil {
		return nil, nil // NULL = defaults
	}
	if o.ptr == nil {
		return nil, ErrClosed
	}
	return o.ptr, nil
}

// callWith runs one C call with o's handle (nil o = NULL = defaults), keeping
// o alive until it returns; a closed o gives ErrClosed.
func callWith(o *Options, f func(op *C.sogmm_options) C.sogmm_status) error {
	op, err := o.raw()
	if err != nil {
		return err
	}
	defer runtime.KeepAlive(o)
	return call(func() C.sogmm_status { return f(op) })
}

// do runs one C call on o's handle, keeping o alive until it returns.
func (o *Options) do(f func(p *C.sogmm_options) C.sogmm_status) error {
	if o == nil || o.ptr == nil {
		return ErrClosed
	}
	defer runtime.KeepAlive(o)
	return call(func() C.sogmm_status { return f(o.ptr) })
}

// SetF64 sets an f64 key.
func (o *Options) SetF64(key Key, v float64) error {
	return o.do(func(p *C.sogmm_options) C.sogmm_status {
		return C.sogmm_options_set_f64(p, C.sogmm_key(key), C.double(v))
	})
}

// SetI64 sets an i64 key.
func (o *Options) SetI64(key Key, v int64) error {
	return o.do(func(p *C.sogmm_options) C.sogmm_status {
		return C.sogmm_options_set_i64(p, C.sogmm_key(key), C.int64_t(v))
	})
}

// GetF64 reads an f64 key.
func (o *Options) GetF64(key Key) (float64, error) {
	var v C.double
	err := o.do(func(p *C.sogmm_options) C.sogmm_status { return C.sogmm_options_get_f64(p, C.sogmm_key(key), &v) })
	return float64(v), err
}

// GetI64 reads an i64 key.
func (o *Options) GetI64(key Key) (int64, error) {
	var v C.int64_t
	err := o.do(func(p *C.sogmm_options) C.sogmm_status { return C.sogmm_options_get_i64(p, C.sogmm_key(key), &v) })
	return int64(v), err
}

// Clone is a deep copy.
func (o *Options) Clone() (*Options, error) {
	c := &Options{}
	var ptr *C.sogmm_options // a local, as in NewOptions
	if err := o.do(func(p *C.sogmm_options) C.sogmm_status { return C.sogmm_options_clone(&ptr, p) }); err != nil {
		return nil, err
	}
	c.ptr = ptr
	c.progress = o.progress
	runtime.SetFinalizer(c, (*Options).Close)
	return c, nil
}

// copyOrDefaults is a new handle: a Clone of o, or the defaults for a nil o.
func (o *Options) copyOrDefaults() (*Options, error) {
	if o == nil {
		return NewOptions()
	}
	return o.Clone()
}

// OnProgress makes every call given these options report to fn (see
// ProgressFunc); nil removes it. A map keeps the one of the options it was
// created with for its inserts and flushes.
func OnProgress(fn ProgressFunc) Option {
	return func(o *Options) error {
		if o == nil || o.ptr == nil {
			return ErrClosed
		}
		o.progress = fn
		return nil
	}
}

// F64 sets any f64 key (e.g. an experimental one).
func F64(key Key, v float64) Option { return func(o *Options) error { return o.SetF64(key, v) } }

// I64 sets any i64 key.
func I64(key Key, v int64) Option { return func(o *Options) error { return o.SetI64(key, v) } }

func boolI64(b bool) int64 {
	if b {
		return 1
	}
	return 0
}

// Bandwidth of the mean shift (default 0.02).
func Bandwidth(v float64) Option { return F64(OptBandwidth, v) }

// NComponents: fixed K; 0 = self-organizing (default).
func NComponents(k int64) Option { return I64(OptNComponents, k) }

// Tol is the EM stop tolerance (default 1e-3).
func Tol(v float64) Option { return F64(OptTol, v) }

// TolStandardErrors c > 0 also stops EM when a pass changes the mean
// log-likelihood by less than c of its standard error (the per-point
// log-likelihoods' spread over sqrt(N)); 0 = Tol alone (default). See
// SOGMM_OPT_TOL_STANDARD_ERRORS in sogmm.h.
func TolStandardErrors(c float64) Option { return F64(OptTolStandardErrors, c) }

// RegCovar sets one floor, added to all four covariance diagonals in each
// M-step (>= 0, finite in float32), or RegCovarAuto (the default).
func RegCovar(v float64) Option { return F64(OptRegCovar, v) }

// RegCovarAuto, as RegCovar's value (the default), derives the floors from the
// data: 1e-6 x 100^k on x, y and z, 10^k the power of ten nearest the points'
// median distance from their coordinate-wise median, and on gray, 10^k the
// smallest power of ten not below the gray range (1e-6 and 1e-6 for a room with
// gray in [0, 1]). A fitted model records the spatial floor (InfoFitRegCovar).
const RegCovarAuto = float64(C.SOGMM_REG_COVAR_AUTO)

// MaxIter bounds EM iterations (default 100).
func MaxIter(n int64) Option { return I64(OptMaxIter, n) }

// Seed of k-means++ (default 0); stored as the uint64's bits.
func Seed(s uint64) Option { return I64(OptSeed, int64(s)) }

// Threads of a fit, and of the queries given these options (ScoreSamplesWith,
// RegressGrayWith: the same bits for any count); 0 = all cores (default).
func Threads(n int64) Option { return I64(OptThreads, n) }

// NInit runs of k-means++ + EM (default 1).
func NInit(n int64) Option { return I64(OptNInit, n) }

// DequantiseDepth forces the depth-quantisation floor on or off. The default,
// DequantiseAuto, floors RGB-D frames (FitRGBD) and not point arrays.
func DequantiseDepth(on bool) Option {
	if on {
		return I64(OptDequantiseDepth, 1)
	}
	return I64(OptDequantiseDepth, 0)
}

// Squarem turns SQUAREM-accelerated EM on (1) or off (0: plain EM, the
// default); see SOGMM_OPT_EM_ACCELERATION in sogmm.h.
func Squarem(on bool) Option {
	if on {
		return I64(OptEmAcceleration, 1)
	}
	return I64(OptEmAcceleration, 0)
}

// DequantiseAuto is OptDequantiseDepth's default value (see sogmm.h).
const DequantiseAuto = int64(C.SOGMM_DEQUANTISE_AUTO)

// Decimation of RGB-D frames (default 1).
func Decimation(d int64) Option { return I64(OptDecimation, d) }

// DepthScale is raw depth units per metre (default 1000).
func DepthScale(v float64) Option { return F64(OptDepthScale, v) }

// DepthRange sets the valid depth range in metres (min exclusive, max inclusive).
func DepthRange(min, max float64) Option {
	return func(o *Options) error { return o.Set(F64(OptDepthMin, min), F64(OptDepthMax, max)) }
}

// ZstdLevel of saved arrays (default 19).
func ZstdLevel(l int64) Option { return I64(OptZstdLevel, l) }

// StoreFloat64 stores arrays as float64 (default false).
func StoreFloat64(b bool) Option { return I64(OptFloat64, boolI64(b)) }

// Compress arrays when saving (default true).
func Compress(b bool) Option { return I64(OptCompress, boolI64(b)) }

// ArrayPrecision > 0 saves each component as integer codes that move its
// mean by at most v of its own standard deviations (format 1.5; bounds:
// SOGMM_OPT_ARRAY_PRECISION in sogmm.h); 0 saves float arrays, bit-exact
// (default). Outside [0, 0.5]: ErrInvalidArg.
func ArrayPrecision(v float64) Option { return F64(OptArrayPrecision, v) }

// VerifyChecksums when loading (default true).
func VerifyChecksums(b bool) Option { return I64(OptVerifyChecksums, boolI64(b)) }

// SampleTruncation in standard deviations (default 2.5; may be +Inf).
func SampleTruncation(v float64) Option { return F64(OptSampleTruncation, v) }

// QueryTruncationNats culls the queries given these options (ScoreSamplesWith,
// RegressGrayWith): 0 = exact (default); > 0 skips a component at a point
// only when its term is provably more than v nats below the point's largest,
// so a score is at most ln(1 + M e^-v) below the exact one. Negative or not
// finite: ErrInvalidArg.
func QueryTruncationNats(v float64) Option { return F64(OptQueryTruncationNats, v) }

// RenderSurfaceSigma sets the evidence a mode along a pixel's ray needs to be
// a surface in Render: 0 = every mode (default); s > 0 = that of one
// component at s sigma, so a ray grazing a nearer object's components shows
// the surface behind. Negative or not finite: ErrInvalidArg.
func RenderSurfaceSigma(v float64) Option { return F64(OptRenderSurfaceSigma, v) }
