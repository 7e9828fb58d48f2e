package sogmm

// #include "sogmm/sogmm.h"
import "C"

import (
	"context"
	"runtime"
)

// MapMergeStats is what MergeMap did.
type MapMergeStats struct {
	Kept    uint64 // this map's components kept
	Removed uint64 // this map's components the other map holds more sharply (removed)
	Added   uint64 // the other map's components added
	Skipped uint64 // the other map's components this map already holds as sharply (left out)
	Frames  uint64 // frame provenance lines added (the other map's frames)
}

// MergeMap merges the map other into m (two robots, one map), otherToThis
// moving the other map's world frame into m's: where both hold a surface the
// sharper view wins instead of both being stacked; the other's frame
// provenance is appended; one revision, carried by deltas
// (sogmm_map_merge_map). Errors (m unchanged): other is m, points pending in
// either map, a pose not finite or not rigid -> ErrInvalidArg; other without
// components -> ErrInvalidData; either map in use -> ErrBusy.
func (m *Map) MergeMap(other *Map, otherToThis [16]float64) (MapMergeStats, error) {
	var st MapMergeStats
	if other == nil || other.ptr == nil {
		return st, ErrClosed
	}
	if other == m {
		return st, invalidArg("a map cannot be merged into itself (merge a copy)")
	}
	defer runtime.KeepAlive(other)
	var out [5]C.uint64_t
	err := other.read("MergeMap", func() error {
		return m.change(context.Background(), "MergeMap", func(p *C.sogmm_map) C.sogmm_status {
			return C.sogmm_map_merge_map(p, other.ptr, (*C.double)(&otherToThis[0]), &out[0])
		})
	})
	if err == nil {
		st = MapMergeStats{uint64(out[0]), uint64(out[1]), uint64(out[2]), uint64(out[3]), uint64(out[4])}
	}
	return st, err
}
