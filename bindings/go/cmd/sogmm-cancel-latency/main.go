// Command sogmm-cancel-latency measures how long FitContext takes to return
// once its context is cancelled about 1 s into a d = 1 fit (issue 16). Input:
// a frame's points as raw float32 rows (x, y, z, gray), as written by
// tools/sogmm-perf/cancel_latency.py --dump FILE.
//
//	go run ./cmd/sogmm-cancel-latency FILE [runs] [delay-seconds]
package main

import (
	"context"
	"encoding/binary"
	"errors"
	"fmt"
	"math"
	"os"
	"sort"
	"strconv"
	"sync/atomic"
	"time"

	"sogmm"
)

func main() {
	if len(os.Args) < 2 {
		fmt.Fprintln(os.Stderr, "usage: sogmm-cancel-latency POINTS.f32 [runs] [delay-seconds]")
		os.Exit(2)
	}
	raw, err := os.ReadFile(os.Args[1])
	if err != nil || len(raw)%16 != 0 {
		fmt.Fprintln(os.Stderr, "sogmm-cancel-latency: cannot read n x 4 float32 points:", err)
		os.Exit(1)
	}
	pts := make([]float32, len(raw)/4)
	for i := range pts {
		pts[i] = math.Float32frombits(binary.LittleEndian.Uint32(raw[4*i:]))
	}
	runs, delay := 5, 1.0
	if len(os.Args) > 2 {
		runs, _ = strconv.Atoi(os.Args[2])
	}
	if len(os.Args) > 3 {
		delay, _ = strconv.ParseFloat(os.Args[3], 64)
	}
	opts, err := sogmm.NewOptions(sogmm.Bandwidth(0.02), sogmm.Seed(0))
	if err != nil {
		panic(err)
	}
	defer opts.Close()
	fmt.Printf("go: d = 1 fit of %d points, context cancelled after %.1f s\n", len(pts)/4, delay)
	var lat []float64
	for r := 0; r < runs; r++ {
		ctx, cancel := context.WithCancel(context.Background())
		var sent atomic.Int64
		timer := time.AfterFunc(time.Duration(delay*float64(time.Second)), func() {
			sent.Store(time.Now().UnixNano())
			cancel()
		})
		m, err := sogmm.Fit(ctx, pts, opts)
		done := time.Now().UnixNano()
		timer.Stop()
		cancel()
		if !errors.Is(err, context.Canceled) {
			m.Close()
			fmt.Fprintln(os.Stderr, "the fit ended before the cancel:", err)
			os.Exit(1)
		}
		lat = append(lat, float64(done-sent.Load())/1e6)
		fmt.Printf("  run %d: %.1f ms\n", r+1, lat[len(lat)-1])
	}
	sort.Float64s(lat)
	fmt.Printf("go cancel latency: median %.1f ms, max %.1f ms over %d runs\n", lat[len(lat)/2], lat[len(lat)-1], runs)
}
