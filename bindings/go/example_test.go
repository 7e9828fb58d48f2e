package sogmm_test

import (
	"context"
	"fmt"
	"log"
	"os"
	"path/filepath"

	"sogmm"
)

// Fits a synthetic RGB-D frame (a tilted plane with three gray bands),
// samples and regresses it, and round-trips it through a .sogmm file.
func Example() {
	const w, h = 160, 120
	depth := make([]uint16, w*h)
	gray := make([]uint8, w*h)
	for i := range depth {
		u := i % w
		depth[i] = uint16(1000 + 500*u/w)
		switch {
		case u < w/3:
			gray[i] = 30
		case u < 2*w/3:
			gray[i] = 120
		default:
			gray[i] = 230
		}
	}
	opts, err := sogmm.NewOptions(sogmm.Bandwidth(0.05), sogmm.Decimation(4), sogmm.Seed(1))
	if err != nil {
		log.Fatal(err)
	}
	defer opts.Close()
	model, err := sogmm.FitRGBD(context.Background(), sogmm.Frame{Depth: depth, Gray8: gray, Width: w, Height: h,
		Fx: 140, Fy: 140, Cx: 79.5, Cy: 59.5}, opts)
	if err != nil {
		log.Fatal(err)
	}
	defer model.Close()
	n, _ := model.NComponents()
	fmt.Println("components:", n)

	samples, _ := model.Sample(context.Background(), 1000, 42, 4, nil)
	fmt.Println("samples:", len(samples)/4)
	g, _, _ := model.RegressGray(context.Background(), []float32{-0.4516, 0, 1.0625, 0.6207, 0, 1.4375}, nil)
	fmt.Printf("gray: %.2f %.2f\n", g[0], g[1])

	dir, _ := os.MkdirTemp("", "sogmm-example")
	defer os.RemoveAll(dir)
	path := filepath.Join(dir, "example.sogmm")
	if err := model.Save(path, nil); err != nil {
		log.Fatal(err)
	}
	loaded, err := sogmm.Load(path, nil)
	if err != nil {
		log.Fatal(err)
	}
	defer loaded.Close()
	ln, _ := loaded.NComponents()
	fmt.Println("reloaded components:", ln)
	// Output:
	// components: 5
	// samples: 1000
	// gray: 0.12 0.90
	// reloaded components: 5
}
