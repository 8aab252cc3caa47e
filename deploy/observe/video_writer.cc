#include "deploy/observe/video_writer.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/error.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libavutil/pixdesc.h>
#include <libswscale/swscale.h>
}

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace vantage {
namespace {

// GIF frame delays below 2 centiseconds are played as 10 by browsers.
constexpr double kMaxGifFps = 50.0;
constexpr int kMinSize = 16;
constexpr int kMaxSize = 8192;

std::string AvError(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = "";
  av_strerror(code, text, sizeof(text));
  return text;
}

struct FormatDeleter {
  void operator()(AVFormatContext* format) const {
    if (format->pb != nullptr && !(format->oformat->flags & AVFMT_NOFILE)) {
      avio_closep(&format->pb);
    }
    avformat_free_context(format);
  }
};
struct CodecDeleter {
  void operator()(AVCodecContext* codec) const { avcodec_free_context(&codec); }
};
struct FrameDeleter {
  void operator()(AVFrame* frame) const { av_frame_free(&frame); }
};
struct PacketDeleter {
  void operator()(AVPacket* packet) const { av_packet_free(&packet); }
};
struct ScaleDeleter {
  void operator()(SwsContext* scale) const { sws_freeContext(scale); }
};

// The path's container (.mp4 or .gif), the size and the frame rate.
absl::Status CheckVideoRequest(const std::string& path, int width, int height,
                               double fps) {
  const std::string lower = absl::AsciiStrToLower(path);
  if (!absl::EndsWith(lower, ".gif") && !absl::EndsWith(lower, ".mp4")) {
    return absl::InvalidArgumentError(absl::StrCat(
        "video '", path, "': unknown extension (use .mp4 or .gif)"));
  }
  if (width % 2 != 0 || height % 2 != 0 || width < kMinSize ||
      height < kMinSize || width > kMaxSize || height > kMaxSize) {
    return absl::InvalidArgumentError(
        absl::StrCat("video size ", width, "x", height,
                     ": width and height must be even "
                     "and in [",
                     kMinSize, ", ", kMaxSize, "]"));
  }
  if (!(fps > 0.0) || !std::isfinite(fps)) {
    return absl::InvalidArgumentError(
        absl::StrCat("video frame rate ", fps, ": must be > 0"));
  }
  return absl::OkStatus();
}

// GIF's own encoder; for MP4, H.264 where FFmpeg has it, else MPEG-4.
absl::StatusOr<const AVCodec*> FindEncoder(const std::string& path, bool gif) {
  const AVCodec* encoder = nullptr;
  if (gif) {
    encoder = avcodec_find_encoder(AV_CODEC_ID_GIF);
  } else {
    encoder = avcodec_find_encoder(AV_CODEC_ID_H264);
    if (encoder == nullptr) encoder = avcodec_find_encoder(AV_CODEC_ID_MPEG4);
  }
  if (encoder == nullptr) {
    return absl::FailedPreconditionError(
        absl::StrCat("video '", path, "': this FFmpeg has no ",
                     gif ? "GIF" : "H.264 or MPEG-4", " encoder"));
  }
  return encoder;
}

void ConfigureEncoder(const AVCodec& encoder, const AVFormatContext& format,
                      int width, int height, AVRational rate, bool gif,
                      AVCodecContext& codec) {
  codec.width = width;
  codec.height = height;
  codec.time_base = av_inv_q(rate);
  codec.framerate = rate;
  // GIF wants a palette: 3-3-2 bit RGB is a fixed one the encoder takes.
  codec.pix_fmt = gif ? AV_PIX_FMT_RGB8 : AV_PIX_FMT_YUV420P;
  if (encoder.id == AV_CODEC_ID_H264) {
    av_opt_set(codec.priv_data, "preset", "veryfast", 0);
    av_opt_set(codec.priv_data, "crf", "23", 0);
  } else if (encoder.id == AV_CODEC_ID_MPEG4) {
    codec.flags |= AV_CODEC_FLAG_QSCALE;
    codec.global_quality = FF_QP2LAMBDA * 4;
    codec.gop_size = 12;
  }
  if (format.oformat->flags & AVFMT_GLOBALHEADER) {
    codec.flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  }
}

// Opens the configured encoder, describes its stream and gives the frame
// its buffers.
absl::Status StartEncoder(const std::string& path, const AVCodec* encoder,
                          AVRational rate, AVCodecContext* codec,
                          AVStream* stream, AVFrame* frame) {
  int code = avcodec_open2(codec, encoder, nullptr);
  if (code < 0) {
    return absl::InternalError(absl::StrCat("video '", path, "': cannot open ",
                                            encoder->name, ": ",
                                            AvError(code)));
  }
  if ((code = avcodec_parameters_from_context(stream->codecpar, codec)) < 0) {
    return absl::InternalError(
        absl::StrCat("video '", path, "': ", AvError(code)));
  }
  stream->time_base = codec->time_base;
  stream->avg_frame_rate = rate;
  frame->format = codec->pix_fmt;
  frame->width = codec->width;
  frame->height = codec->height;
  if ((code = av_frame_get_buffer(frame, 0)) < 0) {
    return absl::ResourceExhaustedError(
        absl::StrCat("video '", path, "': ", AvError(code)));
  }
  return absl::OkStatus();
}

// Opens the file and writes the container's header.
absl::Status StartFile(const std::string& path, AVFormatContext* format) {
  int code = avio_open(&format->pb, path.c_str(), AVIO_FLAG_WRITE);
  if (code < 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "video '", path, "': cannot open it for writing: ", AvError(code)));
  }
  if ((code = avformat_write_header(format, nullptr)) < 0) {
    return absl::InternalError(absl::StrCat(
        "video '", path, "': cannot write the header: ", AvError(code)));
  }
  return absl::OkStatus();
}

}  // namespace

// Declared so that the encoder and its buffers go before the container
// that owns the stream they feed.
struct VideoWriter::Av {
  std::unique_ptr<AVFormatContext, FormatDeleter> format;
  AVStream* stream = nullptr;  // owned by format
  std::unique_ptr<AVCodecContext, CodecDeleter> codec;
  std::unique_ptr<AVFrame, FrameDeleter> frame;
  std::unique_ptr<AVPacket, PacketDeleter> packet;
  std::unique_ptr<SwsContext, ScaleDeleter> scale;
};

absl::StatusOr<std::unique_ptr<VideoWriter>> VideoWriter::Open(
    const std::string& path, int width, int height, double fps) {
  if (absl::Status status = CheckVideoRequest(path, width, height, fps);
      !status.ok()) {
    return status;
  }
  const bool gif = absl::EndsWith(absl::AsciiStrToLower(path), ".gif");
  // FFmpeg's encoders report what they do at the info level.
  av_log_set_level(AV_LOG_ERROR);
  const int keep_every =
      gif ? static_cast<int>(std::ceil(fps / kMaxGifFps - 1e-9)) : 1;
  const AVRational rate = av_d2q(fps / keep_every, 100000);

  auto av = std::make_unique<Av>();
  AVFormatContext* format = nullptr;
  const int code = avformat_alloc_output_context2(
      &format, nullptr, gif ? "gif" : "mp4", path.c_str());
  if (code < 0 || format == nullptr) {
    return absl::InternalError(absl::StrCat("video '", path, "': no ",
                                            gif ? "GIF" : "MP4",
                                            " muxer: ", AvError(code)));
  }
  av->format.reset(format);
  absl::StatusOr<const AVCodec*> encoder = FindEncoder(path, gif);
  if (!encoder.ok()) return encoder.status();
  av->stream = avformat_new_stream(format, nullptr);
  av->codec.reset(avcodec_alloc_context3(*encoder));
  av->frame.reset(av_frame_alloc());
  av->packet.reset(av_packet_alloc());
  if (av->stream == nullptr || av->codec == nullptr || av->frame == nullptr ||
      av->packet == nullptr) {
    return absl::ResourceExhaustedError(
        absl::StrCat("video '", path, "': out of memory"));
  }
  AVCodecContext* codec = av->codec.get();
  ConfigureEncoder(**encoder, *format, width, height, rate, gif, *codec);
  if (absl::Status status = StartEncoder(path, *encoder, rate, codec,
                                         av->stream, av->frame.get());
      !status.ok()) {
    return status;
  }
  av->scale.reset(sws_getContext(width, height, AV_PIX_FMT_RGB24, width, height,
                                 codec->pix_fmt, SWS_BILINEAR, nullptr, nullptr,
                                 nullptr));
  if (av->scale == nullptr) {
    return absl::InternalError(
        absl::StrCat("video '", path, "': swscale cannot convert RGB24 to ",
                     av_get_pix_fmt_name(codec->pix_fmt)));
  }
  if (absl::Status status = StartFile(path, format); !status.ok()) {
    return status;
  }
  return std::unique_ptr<VideoWriter>(new VideoWriter(
      std::move(av), width, height, fps, keep_every, (*encoder)->name));
}

VideoWriter::VideoWriter(std::unique_ptr<Av> av, int width, int height,
                         double fps, int keep_every, std::string codec)
    : av_(std::move(av)),
      width_(width),
      height_(height),
      fps_(fps),
      keep_every_(keep_every),
      codec_(std::move(codec)) {}

VideoWriter::~VideoWriter() = default;

absl::Status VideoWriter::Write(const Frame& frame) {
  if (finished_) {
    return absl::FailedPreconditionError("video: written after Finish");
  }
  if (frame.width != width_ || frame.height != height_ ||
      frame.rgb.size() != static_cast<size_t>(width_) * height_ * 3) {
    return absl::InvalidArgumentError(absl::StrCat(
        "video: a frame of ", frame.width, "x", frame.height, " (",
        frame.rgb.size(), " bytes) for a ", width_, "x", height_, " video"));
  }
  if (frames_seen_++ % keep_every_ != 0) return absl::OkStatus();
  AVFrame* picture = av_->frame.get();
  // The encoder may still hold the previous picture's buffer.
  if (int code = av_frame_make_writable(picture); code < 0) {
    return absl::ResourceExhaustedError(absl::StrCat("video: ", AvError(code)));
  }
  const uint8_t* source[1] = {frame.rgb.data()};
  const int source_stride[1] = {3 * width_};
  sws_scale(av_->scale.get(), source, source_stride, 0, height_, picture->data,
            picture->linesize);
  picture->pts = frames_written_;
  ++frames_written_;
  return Encode(/*flush=*/false);
}

absl::Status VideoWriter::Encode(bool flush) {
  AVCodecContext* codec = av_->codec.get();
  int code = avcodec_send_frame(codec, flush ? nullptr : av_->frame.get());
  if (code < 0) {
    return absl::InternalError(
        absl::StrCat("video: the encoder refused a frame: ", AvError(code)));
  }
  AVPacket* packet = av_->packet.get();
  while (true) {
    code = avcodec_receive_packet(codec, packet);
    if (code == AVERROR(EAGAIN) || code == AVERROR_EOF) return absl::OkStatus();
    if (code < 0) {
      return absl::InternalError(
          absl::StrCat("video: encoding failed: ", AvError(code)));
    }
    av_packet_rescale_ts(packet, codec->time_base, av_->stream->time_base);
    packet->stream_index = av_->stream->index;
    // Takes the packet's data and leaves it blank for the next one.
    code = av_interleaved_write_frame(av_->format.get(), packet);
    if (code < 0) {
      return absl::InternalError(
          absl::StrCat("video: writing failed: ", AvError(code)));
    }
  }
}

absl::Status VideoWriter::Finish() {
  if (finished_) return absl::FailedPreconditionError("video: finished twice");
  finished_ = true;
  if (absl::Status status = Encode(/*flush=*/true); !status.ok()) {
    return status;
  }
  if (int code = av_write_trailer(av_->format.get()); code < 0) {
    return absl::InternalError(
        absl::StrCat("video: cannot write the trailer: ", AvError(code)));
  }
  if (int code = avio_closep(&av_->format->pb); code < 0) {
    return absl::InternalError(
        absl::StrCat("video: closing the file failed: ", AvError(code)));
  }
  return absl::OkStatus();
}

}  // namespace vantage
