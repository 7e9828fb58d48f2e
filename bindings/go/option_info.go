package sogmm

// #include <stdlib.h>
// #include "sogmm/sogmm.h"
import "C"

import "unsafe"

// OptionInfo is what the library's option registry says of one key
// (sogmm_option_get_info): the single source of every option's default and
// range. For an I64 key the F64 fields hold the same values as doubles.
type OptionInfo struct {
	Key        Key
	Name       string // the C macro, e.g. "SOGMM_OPT_BANDWIDTH"
	IsF64      bool   // set with SetF64 (else SetI64)
	DefaultF64 float64
	LowerF64   float64 // closed hull of the accepted values
	UpperF64   float64
	DefaultI64 int64 // I64 keys only
	LowerI64   int64
	UpperI64   int64
	Range      string // the whole rule in words
	Unit       string // "" when dimensionless
	Doc        string // what the option does
}

// OptionInfoOf returns the registry's row of key; an *Error with
// ErrInvalidArg for an unknown key.
func OptionInfoOf(key Key) (OptionInfo, error) {
	var raw C.sogmm_option_info
	raw.struct_size = C.size_t(unsafe.Sizeof(raw))
	if err := call(func() C.sogmm_status { return C.sogmm_option_get_info(C.sogmm_key(key), &raw) }); err != nil {
		return OptionInfo{}, err
	}
	return OptionInfo{
		Key:        key,
		Name:       C.GoString(raw.name),
		IsF64:      raw._type == C.SOGMM_TYPE_F64,
		DefaultF64: float64(raw.default_f64),
		LowerF64:   float64(raw.lower_f64),
		UpperF64:   float64(raw.upper_f64),
		DefaultI64: int64(raw.default_i64),
		LowerI64:   int64(raw.lower_i64),
		UpperI64:   int64(raw.upper_i64),
		Range:      C.GoString(raw._range),
		Unit:       C.GoString(raw.unit),
		Doc:        C.GoString(raw.doc),
	}, nil
}

// OptionKeys returns every option key of the library, in increasing order.
func OptionKeys() ([]Key, error) {
	var n C.size_t
	if err := call(func() C.sogmm_status { return C.sogmm_option_keys(nil, 0, &n) }); err != nil {
		return nil, err
	}
	keys := make([]C.sogmm_key, int(n))
	if n > 0 {
		if err := call(func() C.sogmm_status { return C.sogmm_option_keys(&keys[0], C.size_t(len(keys)), &n) }); err != nil {
			return nil, err
		}
	}
	out := make([]Key, 0, int(n))
	for _, k := range keys[:int(n)] {
		out = append(out, Key(k))
	}
	return out, nil
}
