package sogmm

import (
	"errors"
	"strings"
	"testing"
)

// The registry's defaults are what a fresh Options holds, for every key.
func TestOptionInfoReportsEveryDefaultAFreshHandleHolds(t *testing.T) {
	o := mustOptions(t)
	keys, err := OptionKeys()
	if err != nil || len(keys) < 31 {
		t.Fatalf("OptionKeys: %v (%d keys)", err, len(keys))
	}
	for i, key := range keys {
		if i > 0 && keys[i-1] >= key {
			t.Fatalf("keys not increasing at %d", i)
		}
		info, err := OptionInfoOf(key)
		if err != nil {
			t.Fatal(err)
		}
		if !strings.HasPrefix(info.Name, "SOGMM_OPT_") || info.Range == "" || info.Doc == "" {
			t.Errorf("key %d: %+v", key, info)
		}
		if info.IsF64 {
			v, err := o.GetF64(key)
			if err != nil || v != info.DefaultF64 || v < info.LowerF64 || v > info.UpperF64 {
				t.Errorf("%s: handle %v (%v), registry %+v", info.Name, v, err, info)
			}
		} else {
			v, err := o.GetI64(key)
			if err != nil || v != info.DefaultI64 || v < info.LowerI64 || v > info.UpperI64 {
				t.Errorf("%s: handle %v (%v), registry %+v", info.Name, v, err, info)
			}
		}
	}
	if _, err := OptionInfoOf(99); !errors.Is(err, ErrInvalidArg) {
		t.Errorf("unknown key: %v", err)
	}
}
