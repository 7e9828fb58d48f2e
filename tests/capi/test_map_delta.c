/* sogmm_map_export_delta / sogmm_map_apply_delta and SOGMM_MAP_REVISION: a
 * receiver fed the deltas in order holds the sender's map bit for bit; a gap,
 * a duplicate and a damaged delta are refused and change nothing.
 * sogmm_map_merge_map: into an empty map it gives the other map, with a copy
 * of itself it adds nothing, its revision travels as a delta, bad input
 * changes nothing. */
#include "test_util.h"

static const double k_identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

static int64_t revision_of(const sogmm_map* map) {
  int64_t r = -1;
  EXPECT_OK(sogmm_map_get_i64(map, SOGMM_MAP_REVISION, &r));
  return r;
}

/* The delta from `since`, in a malloc'ed buffer (size query first). */
static uint8_t* export_delta(const sogmm_map* map, int64_t since, size_t* size) {
  uint8_t* bytes = NULL;
  size_t small = 0;
  EXPECT_OK(sogmm_map_export_delta(map, (uint64_t)since, NULL, NULL, 0, size));
  bytes = (uint8_t*)malloc(*size);
  if (*size > 1) {
    EXPECT_STATUS(sogmm_map_export_delta(map, (uint64_t)since, NULL, bytes, *size - 1, &small),
                  SOGMM_E_BUFFER_TOO_SMALL);
    EXPECT_TRUE(small == *size);
  }
  EXPECT_OK(sogmm_map_export_delta(map, (uint64_t)since, NULL, bytes, *size, size));
  return bytes;
}

/* Bitwise equality of the two maps' exported models. */
static int same_maps(const sogmm_map* a, const sogmm_map* b) {
  sogmm_model *ma = NULL, *mb = NULL;
  size_t m = 0, mbn = 0;
  int same = 0;
  if (sogmm_map_export(&ma, a, NULL) != SOGMM_OK || sogmm_map_export(&mb, b, NULL) != SOGMM_OK) goto done;
  sogmm_model_n_components(ma, &m);
  sogmm_model_n_components(mb, &mbn);
  if (m == mbn) {
    float* wa = (float*)malloc(21 * m * sizeof(float));
    float* wb = (float*)malloc(21 * m * sizeof(float));
    sogmm_model_get_weights_f32(ma, wa, m);
    sogmm_model_get_means_f32(ma, wa + m, 4 * m);
    sogmm_model_get_covariances_f32(ma, wa + 5 * m, 16 * m);
    sogmm_model_get_weights_f32(mb, wb, m);
    sogmm_model_get_means_f32(mb, wb + m, 4 * m);
    sogmm_model_get_covariances_f32(mb, wb + 5 * m, 16 * m);
    same = memcmp(wa, wb, 21 * m * sizeof(float)) == 0;
    free(wa);
    free(wb);
  }
done:
  sogmm_model_free(ma);
  sogmm_model_free(mb);
  return same;
}

int main(void) {
  sogmm_options* o = NULL;
  sogmm_map *sender = NULL, *receiver = NULL;
  float* pts = make_clusters(3000, 7);
  uint8_t* d[3] = {NULL, NULL, NULL};
  size_t size[3] = {0, 0, 0};
  double moved[16];
  int i;

  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_BATCH_SIZE, 100000));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 2));
  REQUIRE_OK(sogmm_map_create(&sender, o));
  REQUIRE_OK(sogmm_map_create(&receiver, NULL));
  EXPECT_TRUE(revision_of(sender) == 0);

  /* Three changes: an insert that only pends, a flush, an insert 3 m away
   * with its flush. */
  REQUIRE_OK(sogmm_map_insert_points_f32(sender, pts, 3000, k_identity));
  d[0] = export_delta(sender, 0, &size[0]);
  REQUIRE_OK(sogmm_map_flush(sender));
  d[1] = export_delta(sender, 1, &size[1]);
  memcpy(moved, k_identity, sizeof moved);
  moved[3] = 3.0;
  REQUIRE_OK(sogmm_map_insert_points_f32(sender, pts, 3000, moved));
  REQUIRE_OK(sogmm_map_flush(sender));
  EXPECT_TRUE(revision_of(sender) == 4);
  d[2] = export_delta(sender, 2, &size[2]);
  {
    size_t untouched = 7;  /* not written on failure */
    EXPECT_STATUS(sogmm_map_export_delta(sender, 5, NULL, NULL, 0, &untouched), SOGMM_E_INVALID_ARG);
    EXPECT_TRUE(untouched == 7);
  }

  REQUIRE_OK(sogmm_map_apply_delta(receiver, d[0], size[0], NULL));
  EXPECT_TRUE(revision_of(receiver) == 1);
  /* A gap: the third delta before the second. */
  EXPECT_STATUS(sogmm_map_apply_delta(receiver, d[2], size[2], NULL), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(strstr(sogmm_last_error(), "revision") != NULL);
  EXPECT_TRUE(revision_of(receiver) == 1);
  REQUIRE_OK(sogmm_map_apply_delta(receiver, d[1], size[1], NULL));
  EXPECT_TRUE(revision_of(receiver) == 2);
  /* A duplicate. */
  EXPECT_STATUS(sogmm_map_apply_delta(receiver, d[1], size[1], NULL), SOGMM_E_INVALID_ARG);
  /* Damaged: a flipped bit in the metadata block (its CRC-32C; the delta's
   * steps are there) at a few positions, and a truncated delta. */
  for (i = 0; i < 4; ++i) {
    const size_t length = (size_t)d[2][24] | (size_t)d[2][25] << 8 | (size_t)d[2][26] << 16;
    const size_t at = 32 + (size_t)(i + 1) * length / 5;
    d[2][at] ^= 0x10;
    EXPECT_TRUE(sogmm_map_apply_delta(receiver, d[2], size[2], NULL) != SOGMM_OK);
    d[2][at] ^= 0x10;
  }
  EXPECT_STATUS(sogmm_map_apply_delta(receiver, d[2], size[2] - 3, NULL), SOGMM_E_FORMAT);
  EXPECT_TRUE(revision_of(receiver) == 2);
  REQUIRE_OK(sogmm_map_apply_delta(receiver, d[2], size[2], NULL));
  EXPECT_TRUE(revision_of(receiver) == 4);
  EXPECT_TRUE(same_maps(sender, receiver));
  EXPECT_STATUS(sogmm_map_apply_delta(NULL, d[2], size[2], NULL), SOGMM_E_NULL_ARG);

  /* SOGMM_OPT_MAP_DELTA_HISTORY 1: only the last revision's change is kept. */
  {
    sogmm_map* bounded = NULL;
    size_t n = 0;
    int64_t history = -1;
    EXPECT_OK(sogmm_options_get_i64(o, SOGMM_OPT_MAP_DELTA_HISTORY, &history));
    EXPECT_TRUE(history == 0); /* the default keeps every revision */
    EXPECT_STATUS(sogmm_options_set_i64(o, SOGMM_OPT_MAP_DELTA_HISTORY, -1), SOGMM_E_INVALID_ARG);
    REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_DELTA_HISTORY, 1));
    REQUIRE_OK(sogmm_map_create(&bounded, o));
    REQUIRE_OK(sogmm_map_insert_points_f32(bounded, pts, 3000, k_identity));
    REQUIRE_OK(sogmm_map_flush(bounded));
    EXPECT_TRUE(revision_of(bounded) == 2);
    EXPECT_OK(sogmm_map_export_delta(bounded, 1, NULL, NULL, 0, &n));
    EXPECT_STATUS(sogmm_map_export_delta(bounded, 0, NULL, NULL, 0, &n), SOGMM_E_INVALID_ARG);
    EXPECT_TRUE(strstr(sogmm_last_error(), "changes from revision 1") != NULL);
    sogmm_map_free(bounded);
  }

  /* sogmm_map_merge_map. sender and receiver hold the same map here. */
  {
    sogmm_map *empty = NULL, *none = NULL, *follower = NULL;
    uint64_t st[5] = {9, 9, 9, 9, 9};
    int64_t n = 0, frames = 0;
    double bad[16];
    uint8_t* m = NULL;
    size_t msize = 0;
    REQUIRE_OK(sogmm_map_create(&empty, NULL));
    REQUIRE_OK(sogmm_map_create(&none, NULL));
    REQUIRE_OK(sogmm_map_create(&follower, NULL));
    REQUIRE_OK(sogmm_map_get_i64(sender, SOGMM_MAP_N_COMPONENTS, &n));
    /* Into an empty map: the other map, bitwise. */
    REQUIRE_OK(sogmm_map_merge_map(empty, sender, k_identity, st));
    EXPECT_TRUE(st[0] == 0 && st[1] == 0 && st[2] == (uint64_t)n && st[3] == 0 && st[4] == 2);
    EXPECT_TRUE(same_maps(empty, sender));
    EXPECT_TRUE(revision_of(empty) == 1);
    /* A follower of the receiver, then the receiver merged with a copy of
     * itself: every component ties with its twin, none is added. */
    m = export_delta(receiver, 0, &msize);
    REQUIRE_OK(sogmm_map_apply_delta(follower, m, msize, NULL));
    free(m);
    REQUIRE_OK(sogmm_map_merge_map(receiver, empty, k_identity, st));
    EXPECT_TRUE(st[0] == (uint64_t)n && st[1] == 0 && st[2] == 0 && st[3] == (uint64_t)n);
    EXPECT_TRUE(same_maps(sender, receiver));
    EXPECT_OK(sogmm_map_get_i64(receiver, SOGMM_MAP_N_FRAMES, &frames));
    EXPECT_TRUE(frames == 4); /* both provenances */
    /* The merge is one revision; the follower takes it as a delta. */
    EXPECT_TRUE(revision_of(receiver) == 5);
    m = export_delta(receiver, 4, &msize);
    REQUIRE_OK(sogmm_map_apply_delta(follower, m, msize, NULL));
    free(m);
    EXPECT_TRUE(revision_of(follower) == 5 && same_maps(follower, receiver));
    /* Bad input: a clear error, the map unchanged. */
    EXPECT_STATUS(sogmm_map_merge_map(receiver, receiver, k_identity, NULL), SOGMM_E_INVALID_ARG);
    EXPECT_TRUE(strstr(sogmm_last_error(), "itself") != NULL);
    EXPECT_STATUS(sogmm_map_merge_map(receiver, NULL, k_identity, NULL), SOGMM_E_NULL_ARG);
    EXPECT_STATUS(sogmm_map_merge_map(receiver, empty, NULL, NULL), SOGMM_E_NULL_ARG);
    memcpy(bad, k_identity, sizeof bad);
    bad[7] = NAN;
    EXPECT_STATUS(sogmm_map_merge_map(receiver, empty, bad, NULL), SOGMM_E_INVALID_ARG);
    EXPECT_TRUE(strstr(sogmm_last_error(), "not finite") != NULL);
    EXPECT_STATUS(sogmm_map_merge_map(receiver, none, k_identity, NULL), SOGMM_E_INVALID_DATA);
    EXPECT_TRUE(strstr(sogmm_last_error(), "no component") != NULL);
    EXPECT_TRUE(revision_of(receiver) == 5 && same_maps(sender, receiver));
    sogmm_map_free(empty);
    sogmm_map_free(none);
    sogmm_map_free(follower);
  }

  for (i = 0; i < 3; ++i) free(d[i]);
  free(pts);
  sogmm_map_free(sender);
  sogmm_map_free(receiver);
  sogmm_options_free(o);
  return test_summary("capi_map_delta");
}
