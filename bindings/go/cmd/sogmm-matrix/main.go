// Command sogmm-matrix is the Go participant of the cross-language matrix
// test (protocol: bindings/matrix/run_matrix.py).
//
//	sogmm-matrix write <points.f32> <out.sogmm>
//	sogmm-matrix read <in.sogmm> <query.f32> <out.bin>
//	sogmm-matrix frame <depth.png> <color image> <out.sogmm>
package main

import (
	"bufio"
	"context"
	"encoding/binary"
	"fmt"
	"math"
	"os"

	"sogmm"
)

func floats(path string) ([]float32, error) {
	b, err := os.ReadFile(path)
	if err != nil {
		return nil, err
	}
	out := make([]float32, len(b)/4)
	for i := range out {
		out[i] = math.Float32frombits(binary.LittleEndian.Uint32(b[4*i:]))
	}
	return out, nil
}

func write(pointsPath, outPath string) error {
	pts, err := floats(pointsPath)
	if err != nil {
		return err
	}
	return fitAndSave(outPath, func(o *sogmm.Options) (*sogmm.Model, error) {
		return sogmm.Fit(context.Background(), pts, o)
	})
}

// fitAndSave fits with the protocol's options (bandwidth 0.05, seed 16, one
// thread, then extra) and saves the model to outPath.
func fitAndSave(outPath string, fit func(o *sogmm.Options) (*sogmm.Model, error), extra ...sogmm.Option) error {
	o, err := sogmm.NewOptions(append([]sogmm.Option{sogmm.Bandwidth(0.05), sogmm.Seed(16), sogmm.Threads(1)}, extra...)...)
	if err != nil {
		return err
	}
	defer o.Close()
	m, err := fit(o)
	if err != nil {
		return err
	}
	defer m.Close()
	return m.Save(outPath, nil)
}

// frame fits an RGB-D frame read by the library's reader (not image/png or
// image/jpeg) with the protocol's intrinsics and options.
func frame(depthPath, colorPath, outPath string) error {
	f, err := sogmm.ReadFrame(depthPath, colorPath)
	if err != nil {
		return err
	}
	f.Fx, f.Fy, f.Cx, f.Cy = 525, 525, 319.5, 239.5
	return fitAndSave(outPath, func(o *sogmm.Options) (*sogmm.Model, error) {
		return sogmm.FitRGBD(context.Background(), f, o)
	}, sogmm.Decimation(2))
}

func read(modelPath, queryPath, outPath string) error {
	q, err := floats(queryPath)
	if err != nil {
		return err
	}
	m, err := sogmm.Load(modelPath, nil)
	if err != nil {
		return err
	}
	defer m.Close()
	w, err1 := m.Weights()
	mu, err2 := m.Means()
	cov, err3 := m.Covariances()
	s, err4 := m.Sample(context.Background(), 256, 2024, 4, nil)
	mean, variance, err5 := m.RegressGray(context.Background(), q, nil)
	score, err6 := m.ScoreSamples(context.Background(), q, 3, nil)
	for _, e := range []error{err1, err2, err3, err4, err5, err6} {
		if e != nil {
			return e
		}
	}
	f, err := os.Create(outPath)
	if err != nil {
		return err
	}
	bw := bufio.NewWriter(f)
	for _, a := range [][]float32{w, mu, cov, s, mean, variance} {
		if err := binary.Write(bw, binary.LittleEndian, a); err != nil {
			return err
		}
	}
	if err := binary.Write(bw, binary.LittleEndian, score); err != nil {
		return err
	}
	if err := bw.Flush(); err != nil {
		return err
	}
	return f.Close()
}

func main() {
	var err error
	switch {
	case len(os.Args) == 4 && os.Args[1] == "write":
		err = write(os.Args[2], os.Args[3])
	case len(os.Args) == 5 && os.Args[1] == "read":
		err = read(os.Args[2], os.Args[3], os.Args[4])
	case len(os.Args) == 5 && os.Args[1] == "frame":
		err = frame(os.Args[2], os.Args[3], os.Args[4])
	default:
		err = fmt.Errorf("usage: sogmm-matrix write <points.f32> <out.sogmm> | read <in.sogmm> <query.f32> <out.bin> | frame <depth.png> <color> <out.sogmm>")
	}
	if err != nil {
		fmt.Fprintln(os.Stderr, "sogmm-matrix:", err)
		os.Exit(1)
	}
}
