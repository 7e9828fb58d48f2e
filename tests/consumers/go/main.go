// Command sogmm-consumer fits two cubes of 64 points, 1 m apart, one dark
// (gray 0.2) and one bright (0.8), saves and loads the model and regresses
// gray at the cubes' centres. With a bandwidth of 0.05 m, far below the gap
// and above the cubes' 0.03 m size, mean shift finds exactly two modes, and
// each centre's gray is its cube's. Exits non-zero unless all of that holds.
// Usage: sogmm-consumer <scratch-dir>
package main

import (
	"context"
	"fmt"
	"math"
	"os"
	"path/filepath"

	"sogmm"
)

func main() {
	if len(os.Args) != 2 {
		fmt.Fprintln(os.Stderr, "usage: sogmm-consumer <scratch-dir>")
		os.Exit(2)
	}
	if err := run(filepath.Join(os.Args[1], "consumer_go.sogmm")); err != nil {
		fmt.Fprintln(os.Stderr, err)
		os.Exit(1)
	}
}

func cubes() []float32 {
	var points []float32
	for c, gray := range []float32{0.2, 0.8} {
		for i := 0; i < 4; i++ {
			for j := 0; j < 4; j++ {
				for k := 0; k < 4; k++ {
					points = append(points, float32(c)+0.01*float32(i), 0.01*float32(j), 1+0.01*float32(k), gray)
				}
			}
		}
	}
	return points
}

func run(path string) error {
	opts, err := sogmm.NewOptions(sogmm.Bandwidth(0.05), sogmm.Seed(1))
	if err != nil {
		return err
	}
	defer opts.Close()
	model, err := sogmm.Fit(context.Background(), cubes(), opts)
	if err != nil {
		return err
	}
	defer model.Close()
	fitted, err := model.NComponents()
	if err != nil {
		return err
	}
	if err := model.Save(path, nil); err != nil {
		return err
	}
	loaded, err := sogmm.Load(path, nil)
	if err != nil {
		return err
	}
	defer loaded.Close()
	m, err := loaded.NComponents()
	if err != nil {
		return err
	}
	gray, _, err := loaded.RegressGray(context.Background(), []float32{0.015, 0.015, 1.015, 1.015, 0.015, 1.015}, nil)
	if err != nil {
		return err
	}
	fmt.Printf("%d components fitted, %d loaded from %s, gray %.3f and %.3f\n", fitted, m, path, gray[0], gray[1])
	if fitted != 2 || m != 2 || math.Abs(float64(gray[0])-0.2) > 0.01 || math.Abs(float64(gray[1])-0.8) > 0.01 {
		return fmt.Errorf("wrong result: expected 2 components and gray 0.2 / 0.8")
	}
	return nil
}
