/* SPDX-License-Identifier: MIT
 *
 * gstfrappepool.cpp: GstFrappePool, buffers of dma-buf frame memory the
 * QPUs read in place, and its offer in the ALLOCATION query.
 */
#include "gstfrappepool.h"

#include <algorithm>
#include <string>
#include <vector>

#include <unistd.h>

#include <gst/allocators/gstdmabuf.h>

#include "frappe_backend.h"

GST_DEBUG_CATEGORY_EXTERN(gst_frappe_detect_debug);
#define GST_CAT_DEFAULT gst_frappe_detect_debug

typedef struct _GstFrappePool GstFrappePool;
typedef struct _GstFrappePoolClass GstFrappePoolClass;

struct _GstFrappePool {
	GstBufferPool parent;
	GstAllocator *allocator; /* wraps the fds as dma-buf memory */
	gchar *backend;          /* whose frame memory */
	GstVideoInfo info;       /* the frames' layout */
	guint size;              /* bytes a buffer */
	gboolean videoMeta;      /* upstream reads the layout from a GstVideoMeta */
};

struct _GstFrappePoolClass {
	GstBufferPoolClass parent_class;
};

GType gst_frappe_pool_get_type(void);
G_DEFINE_TYPE(GstFrappePool, gst_frappe_pool, GST_TYPE_BUFFER_POOL)

#define GST_FRAPPE_POOL(obj) (G_TYPE_CHECK_INSTANCE_CAST((obj), gst_frappe_pool_get_type(), GstFrappePool))

namespace {

/* The frames' layout: with a GstVideoMeta every plane's rows 64-byte
 * aligned, else the caps' default one. */
bool frameLayout(GstCaps *caps, bool videoMeta, GstVideoInfo &info)
{
	if (!caps || !gst_video_info_from_caps(&info, caps))
		return false;
	if (!videoMeta)
		return true;
	GstVideoAlignment align;
	gst_video_alignment_reset(&align);
	for (guint &a : align.stride_align)
		a = frappe::gst::kPoolStrideAlign - 1;
	return gst_video_info_align(&info, &align);
}

} /* namespace */

static const gchar **gst_frappe_pool_get_options(GstBufferPool *)
{
	static const gchar *options[] = { GST_BUFFER_POOL_OPTION_VIDEO_META, nullptr };
	return options;
}

static gboolean gst_frappe_pool_set_config(GstBufferPool *pool, GstStructure *config)
{
	GstFrappePool *self = GST_FRAPPE_POOL(pool);
	GstCaps *caps = nullptr;
	guint size = 0, min = 0, max = 0;
	if (!gst_buffer_pool_config_get_params(config, &caps, &size, &min, &max)) {
		GST_WARNING_OBJECT(pool, "invalid pool configuration");
		return FALSE;
	}
	const bool meta = gst_buffer_pool_config_has_option(config, GST_BUFFER_POOL_OPTION_VIDEO_META);
	if (!frameLayout(caps, meta, self->info)) {
		GST_WARNING_OBJECT(pool, "caps %" GST_PTR_FORMAT " are not video frames", static_cast<void *>(caps));
		return FALSE;
	}
	self->videoMeta = meta;
	size = std::max<guint>(size, static_cast<guint>(GST_VIDEO_INFO_SIZE(&self->info)));
	self->size = size;
	gst_buffer_pool_config_set_params(config, caps, size, min, max);
	GST_DEBUG_OBJECT(pool, "%s frames of %u bytes, luma stride %d%s", self->backend, size,
			 GST_VIDEO_INFO_PLANE_STRIDE(&self->info, 0), meta ? " (GstVideoMeta)" : "");
	return GST_BUFFER_POOL_CLASS(gst_frappe_pool_parent_class)->set_config(pool, config);
}

/* Once per buffer of the pool, not per frame: buffers are reused. */
static GstFlowReturn gst_frappe_pool_alloc_buffer(GstBufferPool *pool, GstBuffer **buffer,
						  GstBufferPoolAcquireParams *)
{
	GstFrappePool *self = GST_FRAPPE_POOL(pool);
	const guint size = self->size;
	std::string why;
	const int fd = frappe::allocateFrameMemory(self->backend, size, why);
	if (fd < 0) {
		GST_ERROR_OBJECT(pool, "no %s frame memory of %u bytes: %s", self->backend, size, why.c_str());
		return GST_FLOW_ERROR;
	}
	GstMemory *mem = gst_dmabuf_allocator_alloc(self->allocator, fd, size);
	if (!mem) {
		close(fd);
		GST_ERROR_OBJECT(pool, "could not wrap fd %d as dma-buf memory", fd);
		return GST_FLOW_ERROR;
	}
	GstBuffer *buf = gst_buffer_new();
	gst_buffer_append_memory(buf, mem);
	if (self->videoMeta)
		gst_buffer_add_video_meta_full(buf, GST_VIDEO_FRAME_FLAG_NONE, GST_VIDEO_INFO_FORMAT(&self->info),
					       static_cast<guint>(GST_VIDEO_INFO_WIDTH(&self->info)),
					       static_cast<guint>(GST_VIDEO_INFO_HEIGHT(&self->info)),
					       GST_VIDEO_INFO_N_PLANES(&self->info), self->info.offset, self->info.stride);
	*buffer = buf;
	return GST_FLOW_OK;
}

static void gst_frappe_pool_finalize(GObject *object)
{
	GstFrappePool *self = GST_FRAPPE_POOL(object);
	gst_object_unref(self->allocator);
	g_free(self->backend);
	G_OBJECT_CLASS(gst_frappe_pool_parent_class)->finalize(object);
}

static void gst_frappe_pool_init(GstFrappePool *self)
{
	self->allocator = gst_dmabuf_allocator_new();
	gst_video_info_init(&self->info);
}

static void gst_frappe_pool_class_init(GstFrappePoolClass *klass)
{
	GObjectClass *gobject_class = G_OBJECT_CLASS(klass);
	GstBufferPoolClass *pool_class = GST_BUFFER_POOL_CLASS(klass);
	gobject_class->finalize = gst_frappe_pool_finalize;
	pool_class->get_options = gst_frappe_pool_get_options;
	pool_class->set_config = gst_frappe_pool_set_config;
	pool_class->alloc_buffer = gst_frappe_pool_alloc_buffer;
}

namespace frappe::gst {

GstBufferPool *newFramePool(const char *backend)
{
	auto *self = static_cast<GstFrappePool *>(g_object_new(gst_frappe_pool_get_type(), nullptr));
	self->backend = g_strdup(backend);
	GstBufferPool *pool = GST_BUFFER_POOL(self);
	gst_object_ref_sink(pool);
	return pool;
}

bool isFramePool(GstBufferPool *pool)
{
	return pool && G_TYPE_CHECK_INSTANCE_TYPE(pool, gst_frappe_pool_get_type());
}

bool offerFramePool(GstElement *element, GstQuery *query, const char *backend)
{
	GstCaps *caps = nullptr;
	gst_query_parse_allocation(query, &caps, nullptr);
	const bool meta = gst_query_find_allocation_meta(query, GST_VIDEO_META_API_TYPE, nullptr);
	GstVideoInfo info;
	if (!frameLayout(caps, meta, info)) {
		GST_DEBUG_OBJECT(element, "no pool offered: the ALLOCATION query has no video caps");
		return false;
	}
	const auto size = static_cast<guint>(GST_VIDEO_INFO_SIZE(&info));

	/* Offer only memory the backend gives: else upstream allocates as
	 * before and the QPUs' side copies. */
	std::string why;
	const int fd = frappe::allocateFrameMemory(backend, size, why);
	if (fd < 0) {
		GST_DEBUG_OBJECT(element, "no pool offered: %s", why.c_str());
		return false;
	}
	close(fd);

	/* Downstream's pools stay, after ours; buffers it holds come from
	 * ours if upstream takes it, so its minimum is ours too. */
	struct Offer {
		GstBufferPool *pool;
		guint size, min, max;
	};
	std::vector<Offer> others;
	guint min = kPoolMinBuffers;
	while (gst_query_get_n_allocation_pools(query) > 0) {
		Offer o{};
		gst_query_parse_nth_allocation_pool(query, 0, &o.pool, &o.size, &o.min, &o.max);
		gst_query_remove_nth_allocation_pool(query, 0);
		min = std::max(min, o.min);
		others.push_back(o);
	}

	GstBufferPool *pool = newFramePool(backend);
	GstStructure *config = gst_buffer_pool_get_config(pool);
	gst_buffer_pool_config_set_params(config, caps, size, min, 0);
	if (meta)
		gst_buffer_pool_config_add_option(config, GST_BUFFER_POOL_OPTION_VIDEO_META);
	gst_buffer_pool_set_config(pool, config);
	gst_query_add_allocation_pool(query, pool, size, min, 0);
	gst_object_unref(pool);
	for (const Offer &o : others) {
		gst_query_add_allocation_pool(query, o.pool, o.size, o.min, o.max);
		if (o.pool)
			gst_object_unref(o.pool);
	}
	GST_DEBUG_OBJECT(element, "offering a pool of %s frame memory: %u bytes a frame, luma stride %d%s", backend,
			 size, GST_VIDEO_INFO_PLANE_STRIDE(&info, 0), meta ? " (GstVideoMeta)" : "");
	return true;
}

} /* namespace frappe::gst */
