package sogmm

import "sync/atomic"

// atomicCounter counts events across goroutines (finalizers run on their own).
type atomicCounter struct{ n atomic.Int64 }

func (c *atomicCounter) add()       { c.n.Add(1) }
func (c *atomicCounter) get() int64 { return c.n.Load() }
