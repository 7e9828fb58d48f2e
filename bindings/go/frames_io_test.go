package sogmm

import (
	"bytes"
	"errors"
	"image"
	"image/color"
	"image/png"
	"os"
	"path/filepath"
	"strings"
	"testing"
)

// pngOf encodes img with Go's own encoder: an independent writer of the
// pixels the library must read back.
func pngOf(t *testing.T, img image.Image) []byte {
	var b bytes.Buffer
	if err := png.Encode(&b, img); err != nil {
		t.Fatal(err)
	}
	return b.Bytes()
}

func TestDecodeFrameGivesThePixelsOfTheFiles(t *testing.T) {
	depth := image.NewGray16(image.Rect(0, 0, 4, 3))
	rgb := image.NewNRGBA(image.Rect(0, 0, 4, 3))
	want := make([]uint16, 12)
	var wantRGB []uint8
	for i := range want {
		want[i] = uint16(i*5471 + 3)
		depth.SetGray16(i%4, i/4, color.Gray16{Y: want[i]})
		c := color.NRGBA{R: uint8(i * 20), G: uint8(255 - i), B: uint8(i * 7), A: 255}
		rgb.SetNRGBA(i%4, i/4, c)
		wantRGB = append(wantRGB, c.R, c.G, c.B)
	}
	f, err := DecodeFrame(pngOf(t, depth), pngOf(t, rgb))
	if err != nil {
		t.Fatal(err)
	}
	if f.Width != 4 || f.Height != 3 || !equalU16(f.Depth, want) || !bytes.Equal(f.RGB8, wantRGB) || f.Gray8 != nil {
		t.Fatalf("decoded %dx%d depth %v rgb %v", f.Width, f.Height, f.Depth, f.RGB8)
	}
	g, err := DecodeFrame(pngOf(t, depth), nil)
	if err != nil || !bytes.Equal(g.Gray8, make([]uint8, 12)) {
		t.Fatalf("no colour: %v %v", g.Gray8, err)
	}
}

func equalU16(a, b []uint16) bool {
	if len(a) != len(b) {
		return false
	}
	for i := range a {
		if a[i] != b[i] {
			return false
		}
	}
	return true
}

func TestHostileFramesGiveTheDocumentedStatus(t *testing.T) {
	good := pngOf(t, image.NewGray16(image.Rect(0, 0, 4, 3)))
	if _, err := DecodeFrame(good[:len(good)-10], nil); !errors.Is(err, ErrFormat) {
		t.Fatalf("truncated: %v", err)
	}
	if _, err := DecodeFrame(nil, nil); !errors.Is(err, ErrFormat) {
		t.Fatalf("empty: %v", err)
	}
	_, err := DecodeFrame(pngOf(t, image.NewNRGBA(image.Rect(0, 0, 4, 3))), nil)
	if !errors.Is(err, ErrInvalidData) || !strings.Contains(err.Error(), "one channel") {
		t.Fatalf("RGB depth: %v", err)
	}
	if _, err := ReadFrame("/nonexistent/d.png", ""); !errors.Is(err, ErrIO) || !strings.Contains(err.Error(), "/nonexistent/d.png") {
		t.Fatalf("missing: %v", err)
	}
}

func TestTrajectoryRoundTripIsBitwise(t *testing.T) {
	poses := [][16]float64{
		{1, 0, 0, 1.0 / 3, 0, 0.8, -0.6, -2, 0, 0.6, 0.8, 1e-9, 0, 0, 0, 1},
		{1, 0, 0, 4, 0, 1, 0, 5, 0, 0, 1, 6, 0, 0, 0, 1},
	}
	path := filepath.Join(t.TempDir(), "t.log")
	if err := WriteTrajectory(path, poses); err != nil {
		t.Fatal(err)
	}
	tr, err := ReadTrajectory(path)
	if err != nil || len(tr.IDs) != 2 || tr.IDs[1] != 1 || tr.Poses[0] != poses[0] || tr.Poses[1] != poses[1] {
		t.Fatalf("read back %+v, %v", tr, err)
	}
	if err := os.WriteFile(path, []byte("0 0 1\n2 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"), 0o600); err != nil {
		t.Fatal(err)
	}
	if _, err := ReadTrajectory(path); !errors.Is(err, ErrInvalidData) || !strings.Contains(err.Error(), "t.log:5: pose 0 is not a rigid") {
		t.Fatalf("scaled pose: %v", err)
	}
	if err := WriteTrajectory(path, nil); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("no pose: %v", err)
	}
}
